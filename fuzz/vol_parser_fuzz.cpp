// vol_parser_fuzz.cpp: libFuzzer target for the text .vol reader (host/volume/vol_io.cpp).
//
// Input: the bytes of a .vol file, read through parseVol from memory (loadVol is parseVol on the
// opened file), twice: as loadVol reads it (one buffer larger than the input) and in chunks of
// 16-63 bytes (picked by the input's size), which puts tokens across chunk boundaries.
//
// Contract: a grid whose values are finite and >= 0 with nx*ny*nz of them, or narval::InputError
// with one line "fuzz.vol: ..." in which every token it quotes ('...') is in the input (non-
// printables shown as '?', long ones cut short with "..."); both reads give the same grid or the
// same message when no token is as long as the chunk (a token that fills a chunk is rejected as
// too long, by design). Any other exception, crash, sanitizer report, leak or allocation over
// -malloc_limit_mb is a finding (fuzz_check.h).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>

#include "fuzz_check.h"
#include "volume/dense_grid.h"

namespace {

const std::string kPath = "fuzz.vol";

struct Outcome {
  bool ok = false;
  std::string error;  // the InputError's message when !ok
  narval::DenseGrid grid;
};

// The input as messages show it: vol_io.cpp's showToken writes non-printables as '?'.
std::string shown(const std::string& bytes) {
  std::string s = bytes;
  for (char& c : s)
    if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
  return s;
}

// Every token quoted in `message` ('A B...' after "found " or "number: ") occurs in the input.
void checkQuotedTokens(const std::string& message, const std::string& bytes) {
  for (const char* lead : {"found '", "is not a number: '"}) {
    const size_t open = message.find(lead);
    if (open == std::string::npos) continue;
    const size_t from = open + std::strlen(lead), close = message.rfind('\'');
    if (close == std::string::npos || close < from) narval::fuzz::fail("unbalanced quotes: " + message);
    std::istringstream words(message.substr(from, close - from));
    const std::string input = shown(bytes);
    for (std::string w; words >> w;) {
      if (w.size() > 3 && w.compare(w.size() - 3, 3, "...") == 0) w.resize(w.size() - 3);
      if (w != "" && w != "..." && input.find(w) == std::string::npos)
        narval::fuzz::fail("message quotes '" + w + "', which is not in the input: " + message);
    }
  }
}

Outcome read(const std::string& bytes, size_t chunkBytes) {
  std::istringstream in(bytes);
  Outcome out;
  try {
    out.grid = narval::parseVol(in, kPath, chunkBytes);
    out.ok = true;
  } catch (const narval::InputError& e) {
    narval::fuzz::checkInputError(e, kPath);
    out.error = e.what();
    checkQuotedTokens(out.error, bytes);
    return out;
  }
  const narval::DenseGrid& g = out.grid;
  if (g.nx < 1 || g.ny < 1 || g.nz < 1 || g.data.size() != g.voxelCount())
    narval::fuzz::fail("grid dimensions do not match its data");
  for (float v : g.data)
    if (!std::isfinite(v) || v < 0 || v > g.maxValue) narval::fuzz::fail("a density the rule rejects was accepted");
  return out;
}

// The longest run of bytes between .vol whitespace (vol_io.cpp's isSpace).
size_t longestToken(const std::string& bytes) {
  size_t longest = 0, run = 0;
  for (char c : bytes) {
    const bool space = c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == '\n';
    run = space ? 0 : run + 1;
    longest = std::max(longest, run);
  }
  return longest;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const Outcome whole = read(bytes, size_t(1) << 20);
  const size_t chunkBytes = 16 + size % 48;
  const Outcome chunked = read(bytes, chunkBytes);
  if (longestToken(bytes) >= chunkBytes) return 0;
  const bool same = whole.ok == chunked.ok && whole.error == chunked.error &&
                    whole.grid.nx == chunked.grid.nx && whole.grid.ny == chunked.grid.ny &&
                    whole.grid.nz == chunked.grid.nz && whole.grid.data == chunked.grid.data;
  if (!same)
    narval::fuzz::fail("chunked read differs: \"" + (whole.ok ? "a grid" : whole.error) + "\" vs \"" +
                       (chunked.ok ? "a grid" : chunked.error) + "\"");
  return 0;
}
