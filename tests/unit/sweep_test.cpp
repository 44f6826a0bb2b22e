// The sweep's logic without OpenCL (host/analysis/sweep.h): list parsing, names, render order, the
// reference row, speed-ups, the table and the figure's size. A fake renderer stands in for the path
// tracer: its image is a grey level plus noise that shrinks with spp, its time grows with spp.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "analysis/sweep.h"
#include "core/input_error.h"
#include "scene/scene.h"

namespace narval {
namespace {

Scene tinyScene(int width = 6, int height = 4) {
  Scene s;
  s.sourcePath = "tiny.json";
  s.renderer.width = width;
  s.renderer.height = height;
  s.renderer.spp = 100;
  s.renderer.bounces = 3;
  s.renderer.toneMapping = ToneMapping::None;
  return s;
}

// Pixel i of the fake render: 0.5 + (deterministic ±1 pattern) / sqrt(spp) · 0.2 / bounces-ish.
struct FakeRenderer {
  std::vector<std::pair<int, int>> calls;  // (spp, bounces) of every call, warm-up included
  RenderResult operator()(const Scene& s) {
    calls.emplace_back(s.renderer.spp, s.renderer.bounces);
    RenderResult r;
    r.image.width = s.renderer.width;
    r.image.height = s.renderer.height;
    const size_t n = size_t(s.renderer.width) * s.renderer.height;
    for (size_t i = 0; i < n; ++i) {
      const float noise = ((i * 7919u) % 5 == 0 ? 1.0f : -0.25f) * 0.3f / std::sqrt(float(s.renderer.spp));
      const float v = 0.5f + noise - 0.1f / float(1 + s.renderer.bounces);
      r.image.rgb.insert(r.image.rgb.end(), {v, v, v});
    }
    r.stats.algorithm = algorithmName(s.renderer.algorithm);
    r.stats.device = "fake device";
    r.stats.spp = s.renderer.spp;
    r.stats.bounces = s.renderer.bounces;
    r.stats.seconds = 0.001 * s.renderer.spp * (1 + s.renderer.bounces);
    return r;
  }
};

SweepRenderer wrap(FakeRenderer& f) {
  return [&f](const Scene& s) { return f(s); };
}

TEST(SweepList, ParsesCommaSeparatedPositiveIntegers) {
  EXPECT_EQ(parseSweepList("10,100,1000,10000", "--spp"), (std::vector<int>{10, 100, 1000, 10000}));
  EXPECT_EQ(parseSweepList(" 5 , 35,1000", "--bounces"), (std::vector<int>{5, 35, 1000}));
  EXPECT_EQ(parseSweepList("7", "--spp"), (std::vector<int>{7}));
}

TEST(SweepList, RejectsAnythingElseWithOneLine) {
  for (const std::string bad : {"x", "", "1,,2", "1,", ",1", "0", "1,-2", "1.5", "1;2", "99999999999", "1 2"}) {
    try {
      parseSweepList(bad, "--spp");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), "--spp: expected a comma-separated list of positive integers, got '" + bad + "'");
    }
  }
  try {
    parseSweepList("10,100,10", "--bounces");
    ADD_FAILURE() << "accepted a repeated value";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "--bounces: 10 is listed twice in '10,100,10'");
  }
}

TEST(SweepNames, FilesAndLabels) {
  EXPECT_EQ(sweepFileName(SweepParameter::Spp, 10), "spp_00010.exr");
  EXPECT_EQ(sweepFileName(SweepParameter::Spp, 100000), "spp_100000.exr");
  EXPECT_EQ(sweepFileName(SweepParameter::Bounces, 35), "bounces_0035.exr");
  EXPECT_EQ(sweepLabel(SweepParameter::Spp, 10000), "10000 spp");
  EXPECT_EQ(sweepLabel(SweepParameter::Bounces, 35), "35 bounces");
  EXPECT_EQ(sweepLabel(SweepParameter::Bounces, 1), "1 bounce");
}

TEST(RunSweep, RendersLargestFirstAndTheReferenceRowIsExact) {
  FakeRenderer fake;
  SweepSpec spec;
  spec.parameter = SweepParameter::Spp;
  spec.values = {10, 1000, 100};
  std::vector<int> seen;
  const SweepResult r = runSweep(tinyScene(), spec, wrap(fake), [&](const SweepRow& row) { seen.push_back(row.value); });
  // A 1-spp warm-up at the smallest value, then largest first; bounces stay the scene's.
  ASSERT_EQ(fake.calls.size(), 4u);
  EXPECT_EQ(fake.calls[0], std::make_pair(1, 3));
  EXPECT_EQ(fake.calls[1], std::make_pair(1000, 3));
  EXPECT_EQ(fake.calls[2], std::make_pair(100, 3));
  EXPECT_EQ(fake.calls[3], std::make_pair(10, 3));
  EXPECT_EQ(seen, (std::vector<int>{1000, 100, 10}));
  ASSERT_EQ(r.rows.size(), 3u);
  EXPECT_EQ(r.fixedValue, 3);
  EXPECT_EQ(r.device, "fake device");
  EXPECT_EQ(r.speedupBaseline, 1000);

  const SweepRow& ref = r.rows[0];
  EXPECT_TRUE(ref.isReference);
  EXPECT_EQ(ref.speedup, 1.0);
  EXPECT_EQ(ref.dE76.mean, 0.0);
  EXPECT_EQ(ref.dE76.jndPercent, 0.0);
  EXPECT_EQ(ref.dE2000.mean, 0.0);
  EXPECT_EQ(ref.dE2000.jndPercent, 0.0);
  EXPECT_EQ(ref.dE76Map, std::vector<float>(24, 0.0f));
  for (size_t i = 1; i < 3; ++i) {
    EXPECT_FALSE(r.rows[i].isReference);
    EXPECT_DOUBLE_EQ(r.rows[i].speedup, ref.seconds / r.rows[i].seconds);
  }
  EXPECT_DOUBLE_EQ(r.rows[1].speedup, 10.0);
  // Less noise, less error.
  EXPECT_GT(r.rows[2].dE76.mean, r.rows[1].dE76.mean);
  EXPECT_GT(r.rows[1].dE76.mean, 0.0);
  EXPECT_GT(r.rows[2].dE2000.mean, 0.0);
}

TEST(RunSweep, BouncesKeepTheScenesSpp) {
  FakeRenderer fake;
  SweepSpec spec;
  spec.parameter = SweepParameter::Bounces;
  spec.values = {5, 50};
  spec.warmUp = false;
  const SweepResult r = runSweep(tinyScene(), spec, wrap(fake));
  ASSERT_EQ(fake.calls.size(), 2u);
  EXPECT_EQ(fake.calls[0], std::make_pair(100, 50));
  EXPECT_EQ(fake.calls[1], std::make_pair(100, 5));
  EXPECT_EQ(r.fixedValue, 100);
  EXPECT_EQ(r.rows[0].value, 50);
}

TEST(RunSweep, ExternalReferenceComparesEveryRender) {
  FakeRenderer fake;
  ImageRGB reference = fake(tinyScene()).image;  // the fake at 100 spp, 3 bounces
  fake.calls.clear();
  SweepSpec spec;
  spec.parameter = SweepParameter::Spp;
  spec.values = {100, 10};
  spec.reference = &reference;
  spec.referenceName = "ref.exr";
  const SweepResult r = runSweep(tinyScene(), spec, wrap(fake));
  EXPECT_EQ(r.referenceFile, "ref.exr");
  ASSERT_EQ(r.rows.size(), 2u);
  EXPECT_FALSE(r.rows[0].isReference);
  EXPECT_EQ(r.rows[0].speedup, 1.0);  // against the largest value rendered
  EXPECT_DOUBLE_EQ(r.rows[1].speedup, 10.0);
  EXPECT_EQ(r.rows[0].dE76.mean, 0.0);  // the same image as the reference
  EXPECT_GT(r.rows[1].dE76.mean, 0.0);
  EXPECT_EQ(r.speedupBaseline, 100);
  const nlohmann::ordered_json j = sweepJson(r);
  EXPECT_EQ(j["reference"]["file"], "ref.exr");
  EXPECT_EQ(sweepFigure(r).width > 0, true);
}

TEST(RunSweep, WrongSizeReferenceFailsBeforeRendering) {
  FakeRenderer fake;
  ImageRGB reference;
  reference.width = 5;
  reference.height = 4;
  reference.rgb.assign(60, 0.5f);
  SweepSpec spec;
  spec.values = {10, 1};
  spec.reference = &reference;
  spec.referenceName = "ref.exr";
  try {
    runSweep(tinyScene(), spec, wrap(fake));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "ref.exr: size 5x4 differs from the sweep's 6x4 (use --resolution or a matching reference)");
  }
  EXPECT_TRUE(fake.calls.empty());
  reference.width = 6;
  reference.rgb.assign(72, 0.5f);
  reference.rgb[7] = std::nanf("");
  EXPECT_THROW(checkSweepReference(tinyScene(), reference, "ref.exr"), InputError);
}

TEST(SweepTable, CsvRowsInOrderAndJsonMatches) {
  FakeRenderer fake;
  SweepSpec spec;
  spec.values = {1, 16, 4};
  const SweepResult r = runSweep(tinyScene(), spec, wrap(fake));
  std::istringstream csv(sweepCsv(r));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "value,seconds,speedup,mean_dE76,jnd76_pct,mean_dE2000,jnd2000_pct");
  std::getline(csv, line);
  EXPECT_EQ(line, "16,0.064,1.0,0.0,0.0,0.0,0.0");
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("4,0.016,4.0,", 0), 0u) << line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("1,0.004,16.0,", 0), 0u) << line;
  EXPECT_FALSE(std::getline(csv, line));

  const nlohmann::ordered_json j = sweepJson(r);
  EXPECT_EQ(j["parameter"], "spp");
  EXPECT_EQ(j["fixed"]["bounces"], 3);
  EXPECT_EQ(j["scene"], "tiny.json");
  EXPECT_EQ(j["device"], "fake device");
  EXPECT_EQ(j["reference"]["value"], 16);
  ASSERT_EQ(j["rows"].size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(j["rows"][i]["value"], r.rows[i].value);
    EXPECT_EQ(j["rows"][i]["mean_dE76"].get<double>(), r.rows[i].dE76.mean);
    EXPECT_EQ(j["rows"][i]["jnd2000_pct"].get<double>(), r.rows[i].dE2000.jndPercent);
  }
  EXPECT_EQ(j["rows"][0]["exr"], "spp_00016.exr");
  // The documented columns first, in the table's order.
  std::vector<std::string> keys;
  for (auto it = j["rows"][0].begin(); it != j["rows"][0].end(); ++it) keys.push_back(it.key());
  ASSERT_GE(keys.size(), 7u);
  EXPECT_EQ(std::vector<std::string>(keys.begin(), keys.begin() + 7),
            (std::vector<std::string>{"value", "seconds", "speedup", "mean_dE76", "jnd76_pct", "mean_dE2000",
                                      "jnd2000_pct"}));
}

TEST(SweepFigure, TinyImagesAreEnlargedWideStripsShrunk) {
  FakeRenderer fake;
  SweepSpec spec;
  spec.values = {1, 4, 16};
  spec.warmUp = false;
  // 16x12: columns enlarged by a whole factor (10) to 160 px.
  SweepResult r = runSweep(tinyScene(16, 12), spec, wrap(fake));
  ImageRGB8 fig = sweepFigure(r);
  EXPECT_GE(fig.width, 3 * 160);
  EXPECT_LE(fig.width, 3 * 200);
  EXPECT_EQ(fig.rgb.size(), size_t(fig.width) * fig.height * 3);
  // Seven columns of 900 px would be 6300 px: shrunk under 4000.
  spec.values = {1, 2, 3, 4, 5, 6, 7};
  r = runSweep(tinyScene(900, 60), spec, wrap(fake));
  fig = sweepFigure(r);
  EXPECT_LE(fig.width, 4000);
  EXPECT_GE(fig.width, 3800);
  fig = sweepFigure(r, 2000);
  EXPECT_LE(fig.width, 2000);
}

TEST(SweepFigure, ResizeAveragesAndRepeats) {
  ImageRGB8 src;
  src.width = 2;
  src.height = 1;
  src.rgb = {0, 0, 0, 200, 100, 50};
  const ImageRGB8 half = resizeImage(src, 1, 1);
  EXPECT_EQ(half.rgb, (std::vector<uint8_t>{100, 50, 25}));
  const ImageRGB8 twice = resizeImage(src, 4, 2);
  EXPECT_EQ(twice.rgb, (std::vector<uint8_t>{0, 0, 0, 0, 0, 0, 200, 100, 50, 200, 100, 50,
                                             0, 0, 0, 0, 0, 0, 200, 100, 50, 200, 100, 50}));
}

}  // namespace
}  // namespace narval
