// `narval compare` as a user runs it: exit codes, the one-line errors, the table, the --json keys
// and values on a constructed pair, and the map files.
//
// The pair (derivation in tests/unit/image_compare_test.cpp): 10x8 greys, reference 0.125 (L* 42)
// everywhere; in the test, 12 pixels 0.216 (L* 53.6, ΔE76 11.6) and 20 pixels 0.125·1.01³
// (L* 42.58, ΔE76 0.58). Mean ΔE76 = (12·11.6 + 20·0.58)/80 = 1.885, p95 = max = 11.6,
// JND% = 15; ΔE2000 = ΔL*/S_L for greys.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "cli/cli_fixture.h"
#include "image/image.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

using test::RunResult;

ImageRGB uniform(int w, int h, float v) {
  ImageRGB im;
  im.width = w;
  im.height = h;
  im.rgb.assign(size_t(w) * size_t(h) * 3, v);
  return im;
}

class CompareCli : public test::CliFixture {
 protected:
  void writeImage(const std::string& name, const ImageRGB& im) { writeExr((dir_ / name).string(), im); }
  // The pair above, every value multiplied by `scale` (to be undone by --exposure).
  void writePair(const std::string& ref, const std::string& test, float scale) {
    ImageRGB a = uniform(10, 8, 0.125f * scale), b = a;
    for (int i = 0; i < 32; ++i) {
      const float v = (i < 12 ? 0.216f : 0.125f * 1.030301f) * scale;
      float* p = b.pixel(i % 10, i / 10);
      p[0] = p[1] = p[2] = v;
    }
    writeImage(ref, a);
    writeImage(test, b);
  }
};

double grey2000(double c1, double c2) {
  const double l1 = 116 * c1 - 16, l2 = 116 * c2 - 16, lBar = (l1 + l2) / 2, d = (lBar - 50) * (lBar - 50);
  return std::fabs(l1 - l2) / (1.0 + 0.015 * d / std::sqrt(20.0 + d));
}

void expectPairJson(const nlohmann::json& j) {
  EXPECT_EQ(j["width"], 10);
  EXPECT_EQ(j["height"], 8);
  EXPECT_NEAR(j["mean_dE76"].get<double>(), 1.885, 1e-4);
  EXPECT_NEAR(j["p95_dE76"].get<double>(), 11.6, 1e-4);
  EXPECT_NEAR(j["max_dE76"].get<double>(), 11.6, 1e-4);
  EXPECT_DOUBLE_EQ(j["jnd76_pct"].get<double>(), 15.0);
  const double far00 = grey2000(0.5, 0.6), near00 = grey2000(0.5, 0.505);
  EXPECT_NEAR(j["mean_dE2000"].get<double>(), (12 * far00 + 20 * near00) / 80, 1e-4);
  EXPECT_NEAR(j["p95_dE2000"].get<double>(), far00, 1e-4);
  EXPECT_NEAR(j["max_dE2000"].get<double>(), far00, 1e-4);
  EXPECT_DOUBLE_EQ(j["jnd2000_pct"].get<double>(), 15.0);
}

// relMSE of the pair at `scale` (linear values: the display transform does not enter): 12 pixels
// off by 0.216 − 0.125, 20 by 0.125·0.030301, the other 48 equal, each over ref² + 0.01, all three
// channels alike, averaged over the 80 pixels.
double pairRelMse(double scale) {
  const double ref = 0.125 * scale, far = 0.216 * scale - ref, near = ref * 0.030301, den = ref * ref + 0.01;
  return (12 * far * far / den + 20 * near * near / den) / 80;
}

TEST_F(CompareCli, IdenticalImagesGiveZero) {
  ImageRGB im = uniform(9, 7, 0.0f);
  for (size_t i = 0; i < im.rgb.size(); ++i) im.rgb[i] = float(i % 17) / 8.0f;
  writeImage("a.exr", im);
  writeImage("b.exr", im);
  const RunResult t = run("compare a.exr b.exr");
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_EQ(t.err, "");
  EXPECT_NE(t.out.find("dE76         0.0000     0.0000     0.0000      0.00%"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("dE2000       0.0000     0.0000     0.0000      0.00%"), std::string::npos) << t.out;
  const RunResult j = run("compare a.exr b.exr --json --exposure 2 --tonemap aces");
  ASSERT_EQ(j.code, 0) << j.err;
  const nlohmann::json v = nlohmann::json::parse(j.out);
  for (const char* key :
       {"mean_dE76", "p95_dE76", "max_dE76", "jnd76_pct", "mean_dE2000", "p95_dE2000", "max_dE2000", "jnd2000_pct",
        "rel_mse"})
    EXPECT_EQ(v[key].get<double>(), 0.0) << key;
}

TEST_F(CompareCli, JsonKeysAndValuesOnAConstructedPair) {
  writePair("ref.exr", "test.exr", 1.0f);
  const RunResult r = run("compare ref.exr test.exr --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const nlohmann::json j = nlohmann::json::parse(r.out);
  std::vector<std::string> keys;
  for (const auto& item : j.items()) keys.push_back(item.key());
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(keys, (std::vector<std::string>{"display_transform", "exposure", "height", "jnd2000_pct", "jnd76_pct",
                                            "mask", "max_dE2000", "max_dE76", "mean_dE2000", "mean_dE76", "p95_dE2000",
                                            "p95_dE76", "pixels", "reference", "rel_mse", "test", "tonemap", "width"}));
  EXPECT_EQ(j["mask"], "none");
  EXPECT_EQ(j["pixels"], 80);
  EXPECT_NEAR(j["rel_mse"].get<double>() / pairRelMse(1.0), 1.0, 1e-5);
  EXPECT_EQ(j["display_transform"], "the default: the EXRs record no common display transform");
  EXPECT_EQ(j["reference"], "ref.exr");
  EXPECT_EQ(j["test"], "test.exr");
  EXPECT_EQ(j["exposure"], 0.0);
  EXPECT_EQ(j["tonemap"], "none");
  expectPairJson(j);
}

// --medium-only judges the pixels of the renders' medium channel (render/medium_mask.h). On the
// pair above, a mask of its 20 near pixels (ΔE76 116·(∛(0.125·1.030301) − ∛0.125) = 116·0.5·0.01 =
// 0.58 each) and 8 of its equal ones: mean ΔE76 20·0.58/28, max 0.58, JND 0%, relMSE over 28 pixels.
// The 12 far pixels (ΔE76 11.6) lie outside it: if they counted, the max would be 11.6.
TEST_F(CompareCli, MediumOnlyJudgesThePixelsOfTheMediumMask) {
  writePair("ref.exr", "test.exr", 1.0f);
  ImageRGB ref = uniform(10, 8, 0.125f);
  ExrUintChannel mask{"medium", std::vector<uint32_t>(80, 0u)};
  for (int i = 12; i < 40; ++i) mask.values[size_t(i)] = 1u;
  writeExr((dir_ / "masked_ref.exr").string(), ref, {}, {mask});
  const RunResult r = run("compare masked_ref.exr test.exr --medium-only --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["mask"], "medium");
  EXPECT_EQ(j["pixels"], 28);
  EXPECT_NEAR(j["mean_dE76"].get<double>(), 20 * 0.58 / 28, 1e-3);
  EXPECT_NEAR(j["max_dE76"].get<double>(), 0.58, 1e-3);
  EXPECT_DOUBLE_EQ(j["jnd76_pct"].get<double>(), 0.0);
  const double near = 0.125 * 0.030301;
  EXPECT_NEAR(j["rel_mse"].get<double>() / (20 * near * near / (0.125 * 0.125 + 0.01) / 28), 1.0, 1e-5);
  // Without the flag the mask is not used; the table names the pixels it judged.
  const RunResult all = run("compare masked_ref.exr test.exr --json");
  ASSERT_EQ(all.code, 0) << all.err;
  expectPairJson(nlohmann::json::parse(all.out));
  const RunResult table = run("compare masked_ref.exr test.exr --medium-only");
  ASSERT_EQ(table.code, 0) << table.err;
  EXPECT_NE(table.out.find("over the 28 pixels that see the medium\n"), std::string::npos) << table.out;
  // The test's own mask serves when the reference has none; two masks must agree.
  const RunResult swapped = run("compare ref.exr masked_ref.exr --medium-only --json");
  ASSERT_EQ(swapped.code, 0) << swapped.err;
  EXPECT_EQ(nlohmann::json::parse(swapped.out)["pixels"], 28);
  mask.values[0] = 1u;
  writeExr((dir_ / "other_mask.exr").string(), ref, {}, {mask});
  const RunResult differ = run("compare masked_ref.exr other_mask.exr --medium-only");
  EXPECT_EQ(differ.code, 2);
  EXPECT_EQ(differ.err,
            "narval: other_mask.exr: medium: differs from masked_ref.exr's: the renders are not of the same scene "
            "and camera\n");
  const RunResult none = run("compare ref.exr test.exr --medium-only");
  EXPECT_EQ(none.code, 2);
  EXPECT_EQ(none.err,
            "narval: --medium-only: neither ref.exr nor test.exr has a medium channel (narval render writes it: the "
            "pixels that see the medium)\n");
  EXPECT_EQ(none.out, "");
  writeExr((dir_ / "empty_mask.exr").string(), ref, {}, {ExrUintChannel{"medium", std::vector<uint32_t>(80, 0u)}});
  const RunResult empty = run("compare empty_mask.exr test.exr --medium-only");
  EXPECT_EQ(empty.code, 2);
  EXPECT_EQ(empty.err, "narval: empty_mask.exr: medium: no pixel sees the medium\n");
}

TEST_F(CompareCli, ExposureAndToneMappingApplyToBoth) {
  // Files 4x brighter, compared at −2 stops: the same numbers.
  writePair("ref.exr", "test.exr", 4.0f);
  const RunResult r = run("compare ref.exr test.exr --json --exposure -2");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["exposure"], -2.0);
  expectPairJson(j);
  // relMSE reads the linear files: 4x the values, the ε of 0.01 now small beside ref² = 0.25.
  EXPECT_NEAR(j["rel_mse"].get<double>() / pairRelMse(4.0), 1.0, 1e-5);
  // 1.0 against 2.0: equal once clipped, different through Reinhard (1/2 vs 2/3).
  writeImage("one.exr", uniform(3, 3, 1.0f));
  writeImage("two.exr", uniform(3, 3, 2.0f));
  const RunResult none = run("compare one.exr two.exr --json");
  ASSERT_EQ(none.code, 0) << none.err;
  EXPECT_EQ(nlohmann::json::parse(none.out)["max_dE76"].get<double>(), 0.0);
  const RunResult rh = run("compare one.exr two.exr --json --tonemap reinhard");
  ASSERT_EQ(rh.code, 0) << rh.err;
  const nlohmann::json k = nlohmann::json::parse(rh.out);
  EXPECT_EQ(k["tonemap"], "reinhard");
  EXPECT_NEAR(k["mean_dE76"].get<double>(), 116.0 * (std::cbrt(2.0 / 3.0) - std::cbrt(0.5)), 1e-4);
  EXPECT_DOUBLE_EQ(k["jnd76_pct"].get<double>(), 100.0);
}

TEST_F(CompareCli, TableShowsBothMetrics) {
  writePair("ref.exr", "test.exr", 1.0f);
  const RunResult r = run("compare ref.exr test.exr");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("dE76         1.8850    11.6000    11.6000     15.00%"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dE2000 "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("10x8"), std::string::npos) << r.out;
}

TEST_F(CompareCli, WritesTheMaps) {
  writePair("ref.exr", "test.exr", 1.0f);
  const RunResult r = run("compare ref.exr test.exr --heatmap maps/heat.png --jnd-map maps/jnd.png --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::accept(r.out)) << r.out;  // stdout stays pure JSON
  for (const char* f : {"maps/heat.png", "maps/jnd.png"}) {
    const std::string bytes = test::readFile(dir_ / f);
    ASSERT_GE(bytes.size(), 8u) << f;
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << f;
  }
  EXPECT_EQ(outputs({"ref.exr", "test.exr"}), std::vector<std::string>{"maps"});
}

// Bad input: exit 2, one line on stderr, nothing written.
TEST_F(CompareCli, SizeMismatch) {
  writeImage("ref.exr", uniform(12, 8, 0.5f));
  writeImage("test.exr", uniform(10, 8, 0.5f));
  const RunResult r = run("compare ref.exr test.exr --heatmap heat.png");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: test.exr: size 10x8 differs from the reference's 12x8\n");
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(outputs({"ref.exr", "test.exr"}), std::vector<std::string>{});
}

TEST_F(CompareCli, NonFiniteValuesAreCounted) {
  ImageRGB bad = uniform(6, 4, 0.5f);
  bad.rgb[1] = std::numeric_limits<float>::quiet_NaN();
  bad.rgb[10] = std::numeric_limits<float>::quiet_NaN();
  bad.rgb[20] = std::numeric_limits<float>::infinity();
  writeImage("ref.exr", uniform(6, 4, 0.5f));
  writeImage("test.exr", bad);
  const RunResult r = run("compare ref.exr test.exr --jnd-map jnd.png");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: test.exr: holds 3 non-finite values\n");
  EXPECT_EQ(outputs({"ref.exr", "test.exr"}), std::vector<std::string>{});
  const RunResult s = run("compare test.exr ref.exr");
  EXPECT_EQ(s.code, 2);
  EXPECT_EQ(s.err, "narval: test.exr: holds 3 non-finite values\n");
}

TEST_F(CompareCli, UnreadableInput) {
  writeImage("ref.exr", uniform(4, 4, 0.5f));
  const RunResult r = run("compare ref.exr missing.exr");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("narval: missing.exr: ", 0), 0u) << r.err;
  test::writeFile(dir_ / "junk.exr", "not an exr");
  const RunResult j = run("compare junk.exr ref.exr");
  EXPECT_EQ(j.code, 2);
  EXPECT_EQ(std::count(j.err.begin(), j.err.end(), '\n'), 1) << j.err;
  EXPECT_EQ(j.err.rfind("narval: junk.exr: ", 0), 0u) << j.err;
}

TEST_F(CompareCli, BadOptions) {
  writeImage("a.exr", uniform(4, 4, 0.5f));
  const RunResult tm = run("compare a.exr a.exr --tonemap filmic");
  EXPECT_EQ(tm.code, 2);
  EXPECT_EQ(tm.err, "narval: --tonemap: expected none, reinhard or aces, got 'filmic'\n");
  const RunResult ext = run("compare a.exr a.exr --heatmap heat.jpg");
  EXPECT_EQ(ext.code, 2);
  EXPECT_EQ(ext.err, "narval: --heatmap: the output must be a .png file, got 'heat.jpg'\n");
  const RunResult one = run("compare a.exr");
  EXPECT_EQ(one.code, 2);
  EXPECT_EQ(std::count(one.err.begin(), one.err.end(), '\n'), 1) << one.err;
  EXPECT_EQ(outputs({"a.exr"}), std::vector<std::string>{});
  // Upper case tone-mapping names are accepted.
  EXPECT_EQ(run("compare a.exr a.exr --tonemap ACES").code, 0);
}

// --reference-snapshot (host/analysis/reference_noise.h): a reference of 8192 samples, grey 0.125, and its
// snapshot after the first 2048, where 12 pixels read 0.125 + √3·0.091. The reference's own error is
// then estimated as (1/√3)·(S − R) (k = √(2048/6144)), which puts those 12 pixels at 0.216: ΔE76
// 116·(∛0.216 − ∛0.125) = 116·(0.6 − 0.5) = 11.6 each (L* of a grey Y > 0.008856 is 116·∛Y − 16),
// so a noise-free image would read mean ΔE76 12·11.6/80 = 1.74 and JND 15% against it. The test
// image itself is the reference, at ΔE 0.
std::vector<ExrAttribute> pathtraceAttributes(int begin, int end, const std::string& key, double seed) {
  return {{"narval:algorithm", std::string("pathtrace")},
          {"narval:spp", end - begin},
          {"narval:sample_begin", begin},
          {"narval:sample_end", end},
          {"narval:status", 0},
          {"narval:seed", seed},
          {"narval:render_key", key}};
}

TEST_F(CompareCli, ReferenceSnapshotEstimatesTheReferencesOwnNoise) {
  const ImageRGB ref = uniform(10, 8, 0.125f);
  ImageRGB snap = ref;
  for (int i = 0; i < 12; ++i) {
    float* p = snap.pixel(i % 10, i / 10);
    p[0] = p[1] = p[2] = float(0.125 + std::sqrt(3.0) * (0.216 - 0.125));
  }
  writeExr((dir_ / "ref.exr").string(), ref, pathtraceAttributes(0, 8192, "k1", 1.0));
  writeExr((dir_ / "snap.exr").string(), snap, pathtraceAttributes(0, 2048, "k1", 1.0));
  const RunResult r = run("compare ref.exr ref.exr --tonemap none --exposure 0 --reference-snapshot snap.exr --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["jnd76_pct"].get<double>(), 0.0);
  const nlohmann::json& n = j["reference_noise"];
  EXPECT_EQ(n["snapshot"], "snap.exr");
  EXPECT_EQ(n["snapshot_spp"], 2048);
  EXPECT_EQ(n["reference_spp"], 8192);
  EXPECT_NEAR(n["mean_dE76"].get<double>(), 1.74, 1e-3);
  EXPECT_DOUBLE_EQ(n["jnd76_pct"].get<double>(), 15.0);
  const RunResult t = run("compare ref.exr ref.exr --tonemap none --exposure 0 --reference-snapshot snap.exr");
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.out.find("reference noise (from snap.exr, 2048 of its 8192 samples): a noise-free image would read "
                       "about JND 15.00% (dE76 mean 1.7400)"),
            std::string::npos)
      << t.out;
}

// A snapshot that is not an earlier part of the reference's render: one line naming it and the
// attribute, exit 2.
TEST_F(CompareCli, ReferenceSnapshotMustBeAnEarlierPartOfTheSameRender) {
  const ImageRGB im = uniform(10, 8, 0.125f);
  writeExr((dir_ / "ref.exr").string(), im, pathtraceAttributes(0, 2048, "k1", 1.0));
  writeExr((dir_ / "other.exr").string(), im, pathtraceAttributes(0, 1024, "k2", 1.0));
  writeExr((dir_ / "seed.exr").string(), im, pathtraceAttributes(0, 1024, "k1", 2.0));
  writeExr((dir_ / "more.exr").string(), im, pathtraceAttributes(0, 8192, "k1", 1.0));
  writeImage("plain.exr", im);
  const std::pair<const char*, const char*> cases[] = {
      {"other.exr", "narval: other.exr: narval:render_key: rendered from other settings than ref.exr\n"},
      {"more.exr",
       "narval: more.exr: narval:sample_end: samples [0, 8192) are not a smaller part of the reference's [0, 2048)\n"},
      {"plain.exr", "narval: plain.exr: narval:algorithm: missing: not a narval path-traced render with its samples\n"}};
  for (const auto& [file, message] : cases) {
    const RunResult r = run(std::string("compare ref.exr ref.exr --reference-snapshot ") + file);
    EXPECT_EQ(r.code, 2) << file;
    EXPECT_EQ(r.err, message);
    EXPECT_EQ(r.out, "");
  }
  const RunResult seed = run("compare ref.exr ref.exr --reference-snapshot seed.exr");
  EXPECT_EQ(seed.code, 2);
  EXPECT_EQ(std::count(seed.err.begin(), seed.err.end(), '\n'), 1) << seed.err;
  EXPECT_EQ(seed.err.rfind("narval: seed.exr: narval:seed: seed 2", 0), 0u) << seed.err;
}

}  // namespace
}  // namespace narval
