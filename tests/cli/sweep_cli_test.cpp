// `narval sweep` as a user runs it (dissertation ch. 5, Tables 5.1/5.2, Figs. 5.4/5.8): every file
// written, rows largest first with the reference row exact, time growing with spp, --bounces
// sweeps, --reference, and bad input (exit 2, one line, nothing written).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.h"
#include "image/image.h"
#include "test_support.h"
#include "volume/dense_grid.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

using test::RunResult;

// A table row of sweep.csv.
struct CsvRow {
  int value = 0;
  double seconds = 0, speedup = 0, dE76 = 0, jnd76 = 0, dE2000 = 0, jnd2000 = 0;
};

// Width and height from a PNG's IHDR chunk (0, 0 when the file is not a PNG).
std::pair<uint32_t, uint32_t> pngSize(const std::string& bytes) {
  if (bytes.size() < 24 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 || bytes.compare(12, 4, "IHDR") != 0)
    return {0, 0};
  auto be32 = [&](size_t at) {
    uint32_t v = 0;
    for (size_t i = 0; i < 4; ++i) v = (v << 8) | uint8_t(bytes[at + i]);
    return v;
  };
  return {be32(16), be32(20)};
}

// Each test runs narval in a fresh folder holding a generated 16^3 cloud under Listing 4.1.
class SweepCli : public test::CliFixture {
 protected:
  void SetUp() override {
    writeVdb((dir_ / "cloud.vdb").string(), makeCloud(16, 1));
    test::writeFile(dir_ / "scene.json", test::listing41Json("cloud.vdb"));
  }
  std::vector<CsvRow> readCsv(const std::string& name) {
    std::istringstream in(test::readFile(dir_ / name));
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "value,seconds,speedup,mean_dE76,jnd76_pct,mean_dE2000,jnd2000_pct");
    std::vector<CsvRow> rows;
    while (std::getline(in, line)) {
      CsvRow r;
      char c[6];
      std::istringstream l(line);
      l >> r.value >> c[0] >> r.seconds >> c[1] >> r.speedup >> c[2] >> r.dE76 >> c[3] >> r.jnd76 >> c[4] >> r.dE2000 >>
          c[5] >> r.jnd2000;
      EXPECT_FALSE(l.fail()) << line;
      rows.push_back(r);
    }
    return rows;
  }
  nlohmann::json readJson(const std::string& name) { return nlohmann::json::parse(test::readFile(dir_ / name)); }
  // The files in a folder, sorted.
  std::vector<std::string> filesIn(const std::string& sub) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_ / sub)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
  void expectReferenceRowExact(const CsvRow& r) {
    EXPECT_EQ(r.speedup, 1.0);
    EXPECT_EQ(r.dE76, 0.0);
    EXPECT_EQ(r.jnd76, 0.0);
    EXPECT_EQ(r.dE2000, 0.0);
    EXPECT_EQ(r.jnd2000, 0.0);
  }
};

TEST_F(SweepCli, SppSweepWritesEveryFileLargestFirst) {
  const RunResult r = run("sweep scene.json --spp 1,8,64 --resolution 32x16 -o out");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(filesIn("out"), (std::vector<std::string>{"spp_00001.exr", "spp_00008.exr", "spp_00064.exr",
                                                      "sweep.csv", "sweep.json", "sweep.png"}));
  for (const char* name : {"spp_00001.exr", "spp_00008.exr", "spp_00064.exr"}) {
    const ImageRGB img = readExr((dir_ / "out" / name).string());
    EXPECT_EQ(img.width, 32);
    EXPECT_EQ(img.height, 16);
  }
  EXPECT_EQ(readExrAttributes((dir_ / "out/spp_00008.exr").string()).at("narval:spp"), "8");
  EXPECT_EQ(readExrAttributes((dir_ / "out/spp_00008.exr").string()).at("narval:bounces"), "3");

  const std::vector<CsvRow> rows = readCsv("out/sweep.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].value, 64);
  EXPECT_EQ(rows[1].value, 8);
  EXPECT_EQ(rows[2].value, 1);
  expectReferenceRowExact(rows[0]);
  // 64 times the samples: the 1-spp render is faster, whatever the noise in a small render's
  // timing (measured about 60x on PoCL with 2 cores; asserting only the order leaves a wide margin).
  EXPECT_GT(rows[0].seconds, rows[2].seconds);
  for (const CsvRow& row : rows) EXPECT_GT(row.seconds, 0.0);
  EXPECT_GT(rows[2].speedup, 1.0);
  // Fewer samples, more noise, more error.
  EXPECT_GT(rows[2].dE76, rows[1].dE76);
  EXPECT_GT(rows[1].dE76, 0.0);
  EXPECT_GT(rows[2].jnd76, 0.0);
  EXPECT_GT(rows[2].dE2000, 0.0);

  const nlohmann::json j = readJson("out/sweep.json");
  EXPECT_EQ(j["parameter"], "spp");
  EXPECT_EQ(j["scene"], "scene.json");
  EXPECT_EQ(j["fixed"]["bounces"], 3);
  EXPECT_FALSE(j["device"].get<std::string>().empty());
  EXPECT_EQ(j["reference"]["value"], 64);
  EXPECT_EQ(j["display"]["toneMapping"], "aces");
  ASSERT_EQ(j["rows"].size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const nlohmann::json& row = j["rows"][i];
    EXPECT_EQ(row["value"], rows[i].value);
    EXPECT_EQ(row["seconds"].get<double>(), rows[i].seconds);
    EXPECT_EQ(row["speedup"].get<double>(), rows[i].speedup);
    EXPECT_EQ(row["mean_dE76"].get<double>(), rows[i].dE76);
    EXPECT_EQ(row["jnd76_pct"].get<double>(), rows[i].jnd76);
    EXPECT_EQ(row["mean_dE2000"].get<double>(), rows[i].dE2000);
    EXPECT_EQ(row["jnd2000_pct"].get<double>(), rows[i].jnd2000);
    EXPECT_EQ(row["reference"], i == 0);
  }
  EXPECT_EQ(j["rows"][1]["exr"], "spp_00008.exr");

  // The strip: three columns of a 32-px render enlarged to 160 px, and under 4000 px in any case.
  const auto [w, h] = pngSize(test::readFile(dir_ / "out/sweep.png"));
  EXPECT_GE(w, 3u * 160u);
  EXPECT_LE(w, 4000u);
  EXPECT_GT(h, 3u * 80u);

  // The reference is an ordinary render: `narval render` with the same settings gives its pixels.
  ASSERT_EQ(run("render scene.json --spp 64 --resolution 32x16 -o single.exr").code, 0);
  EXPECT_EQ(readExr((dir_ / "single.exr").string()).rgb, readExr((dir_ / "out/spp_00064.exr").string()).rgb);

  // --reference with that render: the same comparisons as above, every value compared.
  const RunResult again = run("sweep scene.json --spp 8,1 --resolution 32x16 -o out2 --reference out/spp_00064.exr");
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(filesIn("out2"), (std::vector<std::string>{"spp_00001.exr", "spp_00008.exr", "sweep.csv", "sweep.json",
                                                       "sweep.png"}));
  const std::vector<CsvRow> rows2 = readCsv("out2/sweep.csv");
  ASSERT_EQ(rows2.size(), 2u);
  EXPECT_EQ(rows2[0].value, 8);
  EXPECT_EQ(rows2[0].speedup, 1.0);  // against the largest value rendered (the file's time is unknown)
  EXPECT_EQ(rows2[0].dE76, rows[1].dE76);
  EXPECT_EQ(rows2[0].jnd2000, rows[1].jnd2000);
  EXPECT_EQ(rows2[1].dE76, rows[2].dE76);
  const nlohmann::json j2 = readJson("out2/sweep.json");
  EXPECT_EQ(j2["reference"]["file"], "out/spp_00064.exr");
  EXPECT_EQ(j2["speedup_baseline"], 8);
}

TEST_F(SweepCli, BouncesSweepWithFixedSpp) {
  const RunResult r = run("sweep scene.json --bounces 1,8,2 --spp 4 --resolution 16x12 -o b");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(filesIn("b"), (std::vector<std::string>{"bounces_0001.exr", "bounces_0002.exr", "bounces_0008.exr",
                                                    "sweep.csv", "sweep.json", "sweep.png"}));
  const auto attributes = readExrAttributes((dir_ / "b/bounces_0002.exr").string());
  EXPECT_EQ(attributes.at("narval:bounces"), "2");
  EXPECT_EQ(attributes.at("narval:spp"), "4");
  const std::vector<CsvRow> rows = readCsv("b/sweep.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].value, 8);
  EXPECT_EQ(rows[1].value, 2);
  EXPECT_EQ(rows[2].value, 1);
  expectReferenceRowExact(rows[0]);
  const nlohmann::json j = readJson("b/sweep.json");
  EXPECT_EQ(j["parameter"], "bounces");
  EXPECT_EQ(j["fixed"]["spp"], 4);
  EXPECT_EQ(j["width"], 16);
  EXPECT_EQ(j["height"], 12);
  // Both lists given the other way round: the list is swept, the single value fixed.
  const RunResult swapped = run("sweep scene.json --spp 4 --bounces 2,1 --resolution 16x12 -o c");
  ASSERT_EQ(swapped.code, 0) << swapped.err;
  EXPECT_EQ(readJson("c/sweep.json")["parameter"], "bounces");
}

// Bad input: exit 2, exactly the one line, and no output folder.
TEST_F(SweepCli, BadInputWritesNothing) {
  ImageRGB small;
  small.width = 8;
  small.height = 8;
  small.rgb.assign(8 * 8 * 3, 0.5f);
  writeExr((dir_ / "ref.exr").string(), small);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--spp 1,4 --resolution 16x12 --reference ref.exr",
       "ref.exr: size 8x8 differs from the sweep's 16x12 (use --resolution or a matching reference)"},
      {"--spp 1,x", "--spp: expected a comma-separated list of positive integers, got '1,x'"},
      {"--spp 0,4", "--spp: expected a comma-separated list of positive integers, got '0,4'"},
      {"--bounces 5,5,1", "--bounces: 5 is listed twice in '5,5,1'"},
      {"--spp 1,4 --bounces 2,3",
       "--spp, --bounces: sweep exactly one: give one of them as a comma-separated list and the other as a single "
       "value (got '1,4' and '2,3')"},
      {"--spp 4 --bounces 2",
       "--spp, --bounces: sweep exactly one: give one of them as a comma-separated list and the other as a single "
       "value (got '4' and '2')"},
      {"", "--spp, --bounces: give the values to sweep, e.g. --spp 10,100,1000 or --bounces 50,10,5"},
      {"--spp 16", "--spp: a sweep needs at least two values (or --reference FILE.exr)"},
      {"--spp 1,4 --bounces x", "--bounces: expected a non-negative integer, got 'x'"},
      {"--bounces 1,4 --spp 0", "--spp: expected a positive integer, got '0'"},
      {"--spp 1,4 --algorithm lobe", "--algorithm: sweep renders with pathtrace only for now, got 'lobe'"},
      {"--spp 1,4 --resolution 3by2", "--resolution: expected WIDTHxHEIGHT with positive integers, got '3by2'"},
      {"--spp 1,4 --reference missing.exr", ""},
  };
  for (const auto& [args, line] : cases) {
    const RunResult r = run("sweep scene.json " + args + " -o out");
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    if (!line.empty())
      EXPECT_EQ(r.err, "narval: " + line + "\n") << args;
    else
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out")) << args;
  }
  // -o names a file: refused before anything is rendered; the file is left as it was.
  test::writeFile(dir_ / "taken", "precious");
  const RunResult r = run("sweep scene.json --spp 1,4 --resolution 8x4 -o taken");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: -o: 'taken' exists and is not a folder\n");
  EXPECT_EQ(test::readFile(dir_ / "taken"), "precious");
  // -o is required.
  EXPECT_EQ(run("sweep scene.json --spp 1,4").code, 2);
}

}  // namespace
}  // namespace narval

namespace narval {
namespace {

// `compare A B` reports what `sweep` reported for the same pair: both apply the display transform
// of the scene (which the sweep's EXRs record), so compare's default on the reference and a row
// gives the row's ΔE in sweep.json exactly; and the transform it chose is printed.
TEST_F(SweepCli, CompareOfARowAgreesWithTheSweep) {
  nlohmann::json scene = nlohmann::json::parse(test::readFile(dir_ / "scene.json"));
  scene["renderer"]["toneMapping"] = "aces";
  scene["renderer"]["exposure"] = 1.5;
  write("aces.json", scene.dump());
  const test::RunResult r = run("sweep aces.json --spp 1,16 --resolution 24x12 -o out");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json sweep = nlohmann::json::parse(test::readFile(dir_ / "out" / "sweep.json"));
  const test::RunResult c = run("compare out/spp_00016.exr out/spp_00001.exr --json");
  ASSERT_EQ(c.code, 0) << c.err;
  const nlohmann::json j = nlohmann::json::parse(c.out);
  EXPECT_EQ(j["tonemap"], "aces");
  EXPECT_EQ(j["exposure"], 1.5);
  EXPECT_EQ(j["display_transform"], "as both EXRs record it");
  bool found = false;
  for (const nlohmann::json& row : sweep["rows"])
    if (row["value"] == 1) {
      found = true;
      EXPECT_EQ(row["mean_dE76"].get<double>(), j["mean_dE76"].get<double>());
      EXPECT_EQ(row["jnd76_pct"].get<double>(), j["jnd76_pct"].get<double>());
    }
  EXPECT_TRUE(found) << sweep.dump();
  // A flag overrides its half of the transform; the table names where the transform came from.
  const test::RunResult t = run("compare out/spp_00016.exr out/spp_00001.exr --tonemap none");
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.out.find("exposure 1.50 stops, tone mapping none (given, the rest as both EXRs record it)"),
            std::string::npos)
      << t.out;
}

}  // namespace
}  // namespace narval
