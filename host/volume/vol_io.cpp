// vol_io.cpp: the dissertation's text .vol format, the density rule every grid obeys, and loadGrid.
//
// .vol: the first line is "X Y Z" (three positive integers), then X*Y*Z floats, x fastest,
// separated by any whitespace (any line breaks). The input is read in 1 MiB chunks; the header is
// checked against limits and the input's size before anything is allocated. loadVol opens the file
// and calls parseVol, which reads any seekable stream (the fuzzer and tests use bytes in memory).
#include "volume/dense_grid.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "core/input_error.h"

namespace narval {
namespace {

namespace fs = std::filesystem;

constexpr uint64_t kMaxVolValues = uint64_t(1) << 30;

inline bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == '\n'; }

// Whitespace-separated tokens from a stream, with the line each starts on, read in chunks.
class TokenReader {
 public:
  TokenReader(std::istream& in, size_t bufferBytes) : in_(in), buf_(std::max<size_t>(bufferBytes, 2)) {}

  // The next token (valid until the next call); false at the end of the file. A token that fills
  // the whole buffer comes back truncated with tooLong set (it cannot be a number anyway).
  bool next(std::string_view& tok, int64_t& tokLine, bool& tooLong) {
    tooLong = false;
    for (;;) {
      if (pos_ == end_ && !refill()) return false;
      const char c = buf_[pos_];
      if (!isSpace(c)) break;
      if (c == '\n') ++line_;
      ++pos_;
    }
    size_t start = pos_;
    tokLine = line_;
    for (;;) {
      if (pos_ == end_) {
        if (eof_) break;
        if (start == 0 && end_ == buf_.size()) {
          tooLong = true;
          // Keep its start for messages, then skip the rest (which refills the buffer over it).
          cut_.assign(buf_.data(), std::min<size_t>(end_, 64));
          skipRestOfToken();
          tok = cut_;
          return true;
        }
        const size_t len = pos_ - start;
        std::memmove(buf_.data(), buf_.data() + start, len);
        start = 0;
        pos_ = end_ = len;
        if (!readMore()) break;
        continue;
      }
      if (isSpace(buf_[pos_])) break;
      ++pos_;
    }
    tok = std::string_view(buf_.data() + start, pos_ - start);
    return true;
  }

  bool readError() const { return readError_; }

 private:
  // Called with everything consumed (pos_ == end_): starts the buffer afresh.
  bool refill() {
    if (eof_) return false;
    pos_ = end_ = 0;
    return readMore() || end_ > 0;
  }
  bool readMore() {
    in_.read(buf_.data() + end_, std::streamsize(buf_.size() - end_));
    const size_t n = size_t(in_.gcount());
    if (n == 0) {
      if (in_.bad()) readError_ = true;
      eof_ = true;
      return false;
    }
    end_ += n;
    return true;
  }
  void skipRestOfToken() {
    for (;;) {
      if (pos_ == end_) {
        pos_ = end_ = 0;
        if (!readMore()) return;
      }
      if (isSpace(buf_[pos_])) return;
      ++pos_;
    }
  }

  std::istream& in_;
  std::vector<char> buf_;
  std::string cut_;  // the start of the last token that was too long
  size_t pos_ = 0, end_ = 0;
  bool eof_ = false, readError_ = false;
  int64_t line_ = 1;
};

// A token as it may be shown in a message: at most 32 characters, non-printables as '?'.
std::string showToken(std::string_view tok, bool truncated) {
  std::string s;
  for (char c : tok.substr(0, 32)) s += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  if (truncated || tok.size() > 32) s += "...";
  return s;
}

// Parses a float token; false if it is not entirely a number. Out-of-range values become
// +-infinity (overflow) or 0 (underflow), so the density rule reports them.
bool parseFloat(std::string_view tok, float& v) {
  if (tok.size() > 1 && tok[0] == '+' && tok[1] != '-' && tok[1] != '+') tok.remove_prefix(1);
  const char* b = tok.data();
  const char* e = b + tok.size();
  auto r = std::from_chars(b, e, v);
  if (r.ptr != e) return false;
  if (r.ec == std::errc()) return true;
  if (r.ec != std::errc::result_out_of_range) return false;
  double d = 0.0;
  auto rd = std::from_chars(b, e, d);
  if (rd.ptr == e && rd.ec == std::errc()) {
    v = static_cast<float>(d);
    return true;
  }
  const bool negative = tok[0] == '-';
  const size_t ePos = tok.find_first_of("eE");
  const bool underflow = ePos != std::string_view::npos && ePos + 1 < tok.size() && tok[ePos + 1] == '-';
  v = underflow ? 0.0f : (negative ? -std::numeric_limits<float>::infinity() : std::numeric_limits<float>::infinity());
  return true;
}

// A positive integer header field; huge values saturate (the size limit reports them).
bool parseDim(std::string_view tok, uint64_t& v) {
  if (tok.empty()) return false;
  v = 0;
  for (char c : tok) {
    if (c < '0' || c > '9') return false;
    v = std::min<uint64_t>(v * 10 + uint64_t(c - '0'), uint64_t(1) << 40);
  }
  return v > 0;
}

// The header's checks (line 1: three positive integers, a count within the limit and the file's
// size); returns the sizes as declared ("XxYxZ", as written) for messages.
std::string checkVolHeader(const std::string& path, const std::vector<std::string>& header, bool headerOk,
                           const uint64_t dims[3], uint64_t fileSize) {
  if (!headerOk) {
    std::string found;
    for (const std::string& h : header) found += (found.empty() ? "" : " ") + h;
    throw inputError(path, "line 1",
                     "expected the header 'X Y Z' (three positive integers), found " +
                         (header.empty() ? std::string(fileSize == 0 ? "an empty file" : "an empty line")
                                         : "'" + found + "'"));
  }
  const std::string declared = header[0] + "x" + header[1] + "x" + header[2];
  const uint64_t count = dims[0] * dims[1] * dims[2];  // may wrap when over the limit: used only below it
  const bool overLimit = dims[0] > kMaxVolValues || dims[1] > kMaxVolValues || dims[2] > kMaxVolValues ||
                         dims[0] * dims[1] > kMaxVolValues || count > kMaxVolValues;
  if (overLimit) {
    // The count is shown when it fits comfortably in 64 bits (each field below 2^21).
    constexpr uint64_t kShowable = uint64_t(1) << 21;
    const std::string n = (dims[0] < kShowable && dims[1] < kShowable && dims[2] < kShowable)
                              ? " = " + std::to_string(count)
                              : "";
    throw inputError(path, "line 1",
                     "header declares " + declared + n + " values, over the limit of " +
                         std::to_string(kMaxVolValues) + " (2^30)");
  }
  if (count * 2 > fileSize) {
    throw inputError(path, "line 1",
                     "header declares " + declared + " = " + std::to_string(count) +
                         " values, but the file has only " + std::to_string(fileSize) +
                         " bytes (each value needs at least 2)");
  }
  return declared;
}

}  // namespace

void checkDensityValues(DenseGrid& grid, const std::string& key, const std::string& subject) {
  size_t nonFinite = 0, negative = 0, first = grid.data.size();
  float maxValue = 0.0f;
  for (size_t i = 0; i < grid.data.size(); ++i) {
    const float v = grid.data[i];
    if (!std::isfinite(v)) {
      ++nonFinite;
    } else if (v < 0.0f) {
      ++negative;
    } else {
      maxValue = std::max(maxValue, v);
      continue;
    }
    first = std::min(first, i);
  }
  grid.maxValue = maxValue;
  if (nonFinite == 0 && negative == 0) return;
  std::string what;
  if (nonFinite) what = std::to_string(nonFinite) + " non-finite";
  if (negative) what += (what.empty() ? "" : " and ") + std::to_string(negative) + " negative";
  what += nonFinite + negative == 1 ? " value" : " values";
  const size_t nx = size_t(std::max(grid.nx, 1)), ny = size_t(std::max(grid.ny, 1));
  what += " (first at voxel " + std::to_string(first % nx) + " " + std::to_string((first / nx) % ny) + " " +
          std::to_string(first / (nx * ny)) + "); densities must be finite and >= 0";
  throw inputError(grid.source, key, subject + what);
}

DenseGrid loadVol(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throw inputError(path, "", "cannot open the file: no such file");
  if (fs::is_directory(st)) throw inputError(path, "", "cannot open the file: it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw inputError(path, "", std::string("cannot open the file: ") + std::strerror(errno));
  return parseVol(in, path);
}

DenseGrid parseVol(std::istream& in, const std::string& path, size_t chunkBytes) {
  // The size bounds what the header may declare (each value takes at least 2 bytes).
  const std::istream::pos_type start = in.tellg();
  in.seekg(0, std::ios::end);
  const std::istream::pos_type end = in.tellg();
  in.seekg(start);
  if (start == std::istream::pos_type(-1) || end == std::istream::pos_type(-1) || !in)
    throw inputError(path, "", "cannot read the file: cannot determine its size");
  const uint64_t fileSize = uint64_t(end - start);

  // A UTF-8 byte order mark is skipped.
  char bom[3] = {0, 0, 0};
  in.read(bom, 3);
  if (in.gcount() != 3 || std::memcmp(bom, "\xEF\xBB\xBF", 3) != 0) {
    in.clear();
    in.seekg(start);
  }

  // One byte more than the input: a small file never fills the buffer, so no token is cut short.
  TokenReader reader(in, size_t(std::min<uint64_t>(chunkBytes, fileSize + 1)));
  std::string_view tok;
  int64_t line = 0;
  bool tooLong = false;

  // Header: the tokens on line 1.
  std::vector<std::string> header;  // as shown in messages
  uint64_t dims[3] = {0, 0, 0};
  bool headerOk = true;
  size_t headerTokens = 0;
  bool haveFirstValue = false;
  while (reader.next(tok, line, tooLong)) {
    if (line != 1) {
      haveFirstValue = true;
      break;
    }
    if (headerTokens < 3) headerOk = headerOk && !tooLong && parseDim(tok, dims[headerTokens]);
    ++headerTokens;
    if (header.size() < 6) header.emplace_back(showToken(tok, tooLong));
    else header.back() = "...";
  }
  const std::string declared = checkVolHeader(path, header, headerOk && headerTokens == 3, dims, fileSize);
  const uint64_t count = dims[0] * dims[1] * dims[2];

  DenseGrid grid;
  grid.nx = int(dims[0]);
  grid.ny = int(dims[1]);
  grid.nz = int(dims[2]);
  grid.source = path;
  grid.data.resize(count);

  uint64_t found = 0;
  if (haveFirstValue) {
    do {
      if (found < count) {
        float v = 0.0f;
        if (tooLong || !parseFloat(tok, v)) {
          const uint64_t x = found % dims[0], y = (found / dims[0]) % dims[1], z = found / (dims[0] * dims[1]);
          throw inputError(path, "line " + std::to_string(line),
                           "value " + std::to_string(found) + " (x " + std::to_string(x) + ", y " +
                               std::to_string(y) + ", z " + std::to_string(z) + ") is not a number: '" +
                               showToken(tok, tooLong) + "'");
        }
        grid.data[found] = v;
      }
      ++found;
    } while (reader.next(tok, line, tooLong));
  }
  if (reader.readError()) throw inputError(path, "", std::string("read error: ") + std::strerror(errno));
  if (found != count) {
    throw inputError(path, "", "declares " + declared + " = " + std::to_string(count) + " values, found " +
                                   std::to_string(found));
  }
  checkDensityValues(grid, "");
  return grid;
}

std::string gridFileExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

DenseGrid loadGrid(const std::string& path, const std::string& gridName) {
  const std::string ext = gridFileExtension(path);
  if (ext == ".vdb") return loadVdb(path, gridName.empty() ? std::string("density") : gridName);
  if (ext == ".vol") return loadVol(path);
  throw inputError(path, "",
                   "unknown volume file type '" + (ext.empty() ? std::string("(none)") : fs::path(path).extension().string()) +
                       "' (narval reads .vdb and .vol)");
}

}  // namespace narval
