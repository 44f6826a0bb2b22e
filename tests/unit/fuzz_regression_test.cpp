// fuzz_regression_test.cpp: what the libFuzzer targets (fuzz/, scripts/fuzz.sh) found, and the
// parser paths they lean on, each with the exact InputError the input must give. A finding becomes
// a case here: the input inline, the one-line message it must produce instead.
//
// Findings so far:
// - scene_parser_fuzz's one-line check (on an input written by hand to try it): a control
//   character in a JSON string ("type": "emit\nter", a path with a newline) went verbatim into the
//   message, which then spanned two lines. inputError() writes them as escapes (\n \r \t \xHH).
// - by hand, past the fuzzer's input size: JSON nested 10^5 deep overflowed the stack (nlohmann's
//   copy recurses); scene_load.cpp stops at 128 levels. A volume path of 10^5 nested ${...}
//   took quadratic time and memory to expand; scene_path.cpp caps paths at 4096 characters.
// - vol_parser_fuzz (once it checked that quoted tokens are in the input; a first version of the
//   test below had shown it): a token as long as the read buffer was quoted from the buffer after
//   it had been refilled, i.e. as the bytes that followed it. vol_io.cpp's TokenReader keeps a copy.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "core/input_error.h"
#include "scene/scene.h"
#include "test_support.h"
#include "volume/dense_grid.h"

using narval::DenseGrid;
using narval::InputError;

namespace {

using narval::test::inputErrorOf;

std::string sceneError(const std::string& json, const std::vector<std::string>& overrides = {}) {
  return inputErrorOf([&] { narval::parseScene(json, "s.json", overrides); });
}

DenseGrid parseVolText(const std::string& text, size_t chunkBytes = size_t(1) << 20) {
  std::istringstream in(text);
  return narval::parseVol(in, "f.vol", chunkBytes);
}

std::string volError(const std::string& text, size_t chunkBytes = size_t(1) << 20) {
  return inputErrorOf([&] { parseVolText(text, chunkBytes); });
}

// A scene that loads but for the materials given (its volume primitive uses "fog").
std::string sceneWithMaterials(const std::string& materials) {
  return R"({"materials": )" + materials + R"(,
    "primitives": [{"type": "volume", "materialName": "fog"}],
    "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0]},
    "renderer": {"resolution": [4, 4]}})";
}

// ---------------------------------------------------------------- scene parser

TEST(FuzzRegressionScene, ControlCharactersInValuesStayOnOneLine) {
  // The newline (JSON "\n") was copied into the message.
  EXPECT_EQ(sceneError(R"({"materials": [{"name": "x", "type": "emit\nter"}]})"),
            R"(s.json: materials[0].type: unknown value "emit\nter" (allowed: emitter, volume))");
  EXPECT_EQ(sceneError(sceneWithMaterials(R"([{"name": "fog\u0007", "type": "volume",
                 "scattering": [1, 1, 1], "absorption": [0, 0, 0]},
                 {"name": "fog\u0007", "type": "emitter", "albedo": [1, 1, 1]}])")),
            R"(s.json: materials[1].name: duplicate material name "fog\x07" (first used by materials[0]))");
  EXPECT_EQ(sceneError(sceneWithMaterials(R"([{"name": "fog", "type": "volume",
                 "scattering": [1, 1, 1], "absorption": [0, 0, 0], "path": "${A\r\n"}])")),
            R"(s.json: materials[0].path: unterminated ${ in "${A\r\n")");
  // --set values that are not JSON are bare strings, tab and all.
  EXPECT_EQ(sceneError(sceneWithMaterials(R"([{"name": "fog", "type": "volume",
                 "scattering": [1, 1, 1], "absorption": [0, 0, 0]}])"),
                       {"renderer.algorithm=path\ttrace"}),
            R"(s.json: renderer.algorithm: unknown value "path\ttrace" (allowed: pathtrace, raymarch, lobe))");
}

TEST(FuzzRegressionScene, RawControlCharactersAreInvalidJsonOnOneLine) {
  EXPECT_EQ(sceneError("{\"a\x01\": 1}"),
            "s.json: invalid JSON: parse error at line 1, column 4: syntax error while parsing object key - "
            "invalid string: control character U+0001 (SOH) must be escaped to \\u0001; last read: "
            "'\"a<U+0001>'; expected string literal");
}

// Found while fuzzing by hand (past the fuzzer's 4 KiB inputs): a document nested 10^5 deep parsed
// (nlohmann parses without recursion) and then overflowed the stack when the scene copied it.
TEST(FuzzRegressionScene, DeepNestingIsAnErrorNotAStackOverflow) {
  const auto nested = [](size_t levels) {
    return "{\"materials\": " + std::string(levels, '[') + std::string(levels, ']') + "}";
  };
  EXPECT_EQ(sceneError(nested(100000)), "s.json: JSON nested deeper than 128 levels (a scene needs 5)");
  EXPECT_EQ(sceneError(nested(129)), "s.json: JSON nested deeper than 128 levels (a scene needs 5)");
  EXPECT_EQ(sceneError(nested(128)), "s.json: materials[0]: expected an object, got array");
}

// Found while fuzzing by hand: a 2 MB volume path of 10^5 nested ${UNSET:-...} took time and memory
// quadratic in its length to expand (the fuzzer stopped it at 2 GB). Paths are capped at 4096.
TEST(FuzzRegressionScene, LongVolumePathIsAnError) {
  std::string path;
  for (int i = 0; i < 10000; ++i) path += "${NARVAL_UNSET_IN_TESTS:-";
  path += "cloud.vol" + std::string(10000, '}');
  EXPECT_EQ(sceneError(sceneWithMaterials(R"([{"name": "fog", "type": "volume", "scattering": [1, 1, 1],
                 "absorption": [0, 0, 0], "path": ")" + path + "\"}]")),
            "s.json: materials[0].path: must be at most 4096 characters long, got " + std::to_string(path.size()));
}

// ---------------------------------------------------------------- .vol parser

// The chunked reader's boundaries: a token split across two reads, a line break at the end of a
// read, a byte order mark. Every chunk size gives the grid (or the message) of the whole read.
TEST(FuzzRegressionVol, ChunkBoundariesDoNotChangeTheResult) {
  std::string grid = "\xEF\xBB\xBF" "4 4 4\r\n";
  for (int i = 0; i < 64; ++i) grid += std::to_string(i % 7) + "." + std::to_string(i * 37 % 1000) + (i % 5 ? " \t" : "\r\n");
  const DenseGrid whole = parseVolText(grid);
  ASSERT_EQ(whole.data.size(), 64u);
  // Value 61, "5.257", split by two line breaks and a token that is no number: value 62 is on
  // line 17 (header, values 0-60 on lines 2-14 with a break after every fifth, "5" on 15).
  std::string bad = grid;
  bad.insert(bad.size() - 20, "\n\n x1 ");
  const std::string badMessage = "f.vol: line 17: value 62 (x 2, y 3, z 3) is not a number: 'x1'";
  EXPECT_EQ(volError(bad), badMessage);
  for (size_t chunk = 16; chunk <= 80; ++chunk) {
    const DenseGrid g = parseVolText(grid, chunk);
    EXPECT_EQ(g.data, whole.data) << "chunk " << chunk;
    EXPECT_EQ(volError(bad, chunk), badMessage) << "chunk " << chunk;
  }
}

// Found by vol_parser_fuzz (the input below, 16-byte chunks): a token that fills a whole chunk was
// shown from the buffer after skipping its rest had refilled it, i.e. as the bytes that followed.
TEST(FuzzRegressionVol, TokenAsLongAsTheChunkIsShownAsWritten) {
  const std::string found = std::string(" 112infityc") + std::string(12, '\xff') + std::string(10, '\x12') + "\x02" +
                            std::string(5, '\x12') + "\xff\xff\n1 1 1\n";
  const std::string header = "f.vol: line 1: expected the header 'X Y Z' (three positive integers), found ";
  EXPECT_EQ(volError(found, 16), header + "'112infityc??????...'");
  EXPECT_EQ(volError(found), header + "'112infityc??????????????????????...'");
  EXPECT_EQ(volError("12345678901234567890 1 1\n1\n", 16), header + "'1234567890123456... 1 1'");
  // The whole read takes the 21-character value; 16-byte chunks show it cut short.
  const std::string text = "2 1 1\n1 0.123456789012345678901\n";
  EXPECT_EQ(parseVolText(text).data, (std::vector<float>{1.0f, 0.123456789f}));
  EXPECT_EQ(volError(text, 16), "f.vol: line 2: value 1 (x 1, y 0, z 0) is not a number: '0.12345678901234...'");
}

TEST(FuzzRegressionVol, SizeComesFromTheStream) {
  // Only a byte order mark: three bytes, no header.
  EXPECT_EQ(volError("\xEF\xBB\xBF"),
            "f.vol: line 1: expected the header 'X Y Z' (three positive integers), found an empty line");
  // Read from where the stream stands; what lies before does not count towards the size.
  std::istringstream in("ignored\n2 1 1\n0.5 1\n");
  in.seekg(8);
  EXPECT_EQ(narval::parseVol(in, "f.vol").data, (std::vector<float>{0.5f, 1.0f}));
  std::istringstream small("ignored\n2 1 1\n0.5\n");
  small.seekg(8);
  EXPECT_EQ(inputErrorOf([&] { narval::parseVol(small, "f.vol"); }), "f.vol: declares 2x1x1 = 2 values, found 1");
  // A stream without a size cannot be checked against its header before allocating.
  struct ForwardOnly : std::stringbuf {
    using std::stringbuf::stringbuf;
    pos_type seekoff(off_type, std::ios_base::seekdir, std::ios_base::openmode) override { return pos_type(off_type(-1)); }
    pos_type seekpos(pos_type, std::ios_base::openmode) override { return pos_type(off_type(-1)); }
  } buf("1 1 1\n1\n");
  std::istream forward(&buf);
  EXPECT_EQ(inputErrorOf([&] { narval::parseVol(forward, "f.vol"); }),
            "f.vol: cannot read the file: cannot determine its size");
}

}  // namespace
