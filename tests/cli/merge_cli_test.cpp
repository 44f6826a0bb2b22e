// `narval render --samples A:B` and `narval merge` as a user runs them: parts of any split, merged
// in any order, give the bits of one uninterrupted render (the accumulator is exact: accum.h);
// merged files merge again and resume; every refusal is one line naming the part and the
// attribute, exit 2, with nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "cli/cli_fixture.h"
#include "cli/exr_bits.h"
#include "cli/fog_scene.h"
#include "image/image.h"
#include "render/render_exr.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

using test::RunResult;

class MergeCli : public test::CliFixture {
 protected:
  void SetUp() override {
    write("fog.json", test::fogSceneJson(16, 12, 12));
    const RunResult r = run("render fog.json -o whole.exr -q");
    ASSERT_EQ(r.code, 0) << r.err;
  }
  std::string file(const std::string& name) const { return tmp_.file(name); }
  // Renders samples [a, b) of fog.json into NAME.
  void part(const std::string& name, int a, int b, const std::string& extra = "") {
    const RunResult r = run("render fog.json -q -o " + name + " --samples " + std::to_string(a) + ":" +
                            std::to_string(b) + extra);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  // `narval merge PARTS -o out.exr`, expected to refuse with exactly `line` and write nothing.
  void expectRefusal(const std::string& parts, const std::string& line) {
    fs::remove(dir_ / "out.exr");
    const RunResult r = run("merge " + parts + " -o out.exr");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err, "narval: " + line + "\n");
    EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
    EXPECT_FALSE(fs::exists(dir_ / "out.png"));
  }
};

// 12 spp split into 2, 3 and 7 uneven parts, given to merge shuffled: every channel (the image and
// the 13 accumulator channels) equal to the single render's bit for bit; so is the PNG. The merged
// header names the whole range and the total spp.
TEST_F(MergeCli, AnySplitInAnyOrderGivesTheBitsOfOneRender) {
  const std::vector<std::vector<int>> splits = {{0, 5, 12}, {0, 1, 8, 12}, {0, 2, 3, 4, 6, 7, 11, 12}};
  for (size_t k = 0; k < splits.size(); ++k) {
    const std::vector<int>& cut = splits[k];
    std::vector<std::string> names;
    for (size_t i = 0; i + 1 < cut.size(); ++i) {
      names.push_back("s" + std::to_string(k) + "_" + std::to_string(i) + ".exr");
      part(names.back(), cut[i], cut[i + 1]);
    }
    std::string args;  // reversed, then the first moved to the middle: neither order nor sorted
    for (auto it = names.rbegin(); it != names.rend(); ++it) args += " " + *it;
    const std::string merged = "merged" + std::to_string(k) + ".exr";
    const RunResult r = run("merge" + args + " -o " + merged);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string said = "wrote " + merged + " and merged" + std::to_string(k) + ".png (16x12, 12 spp from " +
                             std::to_string(names.size()) + " parts, ";  // then the seconds, which vary
    EXPECT_EQ(r.out.substr(0, said.size()), said);
    SCOPED_TRACE(std::to_string(names.size()) + " parts");
    test::expectSameBits(file("whole.exr"), file(merged));
    EXPECT_EQ(test::readFile(dir_ / "whole.png"), test::readFile(dir_ / ("merged" + std::to_string(k) + ".png")));
    const auto attrs = readExrAttributes(file(merged));
    EXPECT_EQ(attrs.at("narval:spp"), "12");
    EXPECT_EQ(attrs.at("narval:sample_begin"), "0");
    EXPECT_EQ(attrs.at("narval:sample_end"), "12");
    EXPECT_EQ(attrs.at("narval:render_key"), readExrAttributes(file("whole.exr")).at("narval:render_key"));
    EXPECT_EQ(attrs.at("narval:overrides"), "renderer.spp=12");
  }
}

// A part's own image is the mean of its samples, and its header names its range.
TEST_F(MergeCli, APartIsTheImageOfItsSamples) {
  part("p.exr", 4, 7);
  const auto attrs = readExrAttributes(file("p.exr"));
  EXPECT_EQ(attrs.at("narval:sample_begin"), "4");
  EXPECT_EQ(attrs.at("narval:sample_end"), "7");
  EXPECT_EQ(attrs.at("narval:spp"), "3");
  EXPECT_EQ(attrs.at("samplesPerPixel"), "3");
  const RenderPart p = readRenderPart(file("p.exr"));
  long long nan = 0;
  const ImageRGB mean = accumulatorImage(p.accumulator, p.width, p.height, &nan);
  EXPECT_EQ(mean.rgb, readExr(file("p.exr")).rgb);
  // Not the first three samples' image.
  part("q.exr", 0, 3);
  EXPECT_NE(readExr(file("q.exr")).rgb, mean.rgb);
}

// Merged files merge again ([0, 5) + [5, 9) then + [9, 12)), and --resume continues a merged file
// ([0, 9) to 12 spp): both the single render's bits.
TEST_F(MergeCli, MergedFilesMergeAgainAndResume) {
  part("a.exr", 0, 5);
  part("b.exr", 5, 9);
  part("c.exr", 9, 12);
  ASSERT_EQ(run("merge a.exr b.exr -o ab.exr -q").code, 0);
  const RunResult r = run("merge c.exr ab.exr -o abc.exr -q");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  test::expectSameBits(file("whole.exr"), file("abc.exr"));
  const RunResult resumed = run("render fog.json -q -o ab.exr --resume --spp 12");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  test::expectSameBits(file("whole.exr"), file("ab.exr"));
  // --samples with --resume continues a part from where it stopped: [5, 9) to [5, 12) = b + c.
  ASSERT_EQ(run("render fog.json -q -o b.exr --resume --samples 5:12").code, 0);
  ASSERT_EQ(run("merge a.exr b.exr -o ab2.exr -q").code, 0);
  test::expectSameBits(file("whole.exr"), file("ab2.exr"));
}

// Gaps, overlaps, a missing start, a foreign scene, another seed, device or version, an image
// that is not a part, the output among the inputs: one line each, exit 2, nothing written.
TEST_F(MergeCli, RefusalsNameThePartAndTheAttribute) {
  part("a.exr", 0, 4);
  part("b.exr", 4, 8);
  part("c.exr", 8, 12);
  part("late.exr", 6, 12);
  part("seed9.exr", 4, 8, " --seed 9");
  expectRefusal("a.exr c.exr", "c.exr: narval:sample_begin: samples [4, 8) are missing between a.exr [0, 4) and "
                               "this part [8, 12)");
  expectRefusal("b.exr c.exr", "b.exr: narval:sample_begin: the parts start at sample 4: samples [0, 4) are missing");
  expectRefusal("a.exr b.exr late.exr", "late.exr: narval:sample_begin: samples [6, 12) overlap b.exr's [4, 8)");
  expectRefusal("a.exr a.exr b.exr c.exr", "a.exr: narval:sample_begin: samples [0, 4) overlap a.exr's [0, 4)");
  const std::string key = readExrAttributes(file("a.exr")).at("narval:render_key");
  const std::string otherKey = readExrAttributes(file("seed9.exr")).at("narval:render_key");
  ASSERT_NE(key, otherKey);
  expectRefusal("a.exr seed9.exr c.exr",
                "seed9.exr: narval:render_key: '" + otherKey + "' where a.exr has '" + key +
                    "' (renderer.seed is 7 in a.exr, 9 in this part): parts must come from one scene, settings, "
                    "seed, device and narval version");
  // Another device or narval version: the same part with that attribute rewritten.
  const RenderPart b = readRenderPart(file("b.exr"));
  for (const char* attribute : {"narval:device", "narval:version"}) {
    std::vector<ExrAttribute> attrs;
    for (const auto& [name, value] : b.attributes)  // narval's own, as text (what merge reads)
      if (name.rfind("narval:", 0) == 0) attrs.push_back({name, name == attribute ? std::string("elsewhere") : value});
    std::vector<ExrUintChannel> channels = readExrUintChannels(file("b.exr"), test::accumulatorChannels());
    writeExr(file("moved.exr"), readExr(file("b.exr")), attrs, channels);
    expectRefusal("a.exr moved.exr c.exr", std::string("moved.exr: ") + attribute + ": 'elsewhere' where a.exr has '" +
                                               b.attribute(attribute) +
                                               "': parts must come from one scene, settings, seed, device and "
                                               "narval version");
  }
  // A ray-marched image carries no samples.
  ASSERT_EQ(run("render fog.json -q -o rm.exr --algorithm raymarch").code, 0);
  expectRefusal("a.exr rm.exr",
                "rm.exr: narval:algorithm: rendered by raymarch; only path-traced renders carry their samples");
  expectRefusal("a.exr nothing.exr", "nothing.exr: file not found");
  // The output may not be one of its inputs.
  const std::string before = test::readFile(dir_ / "c.exr");
  const RunResult r = run("merge a.exr b.exr c.exr -o c.exr");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: -o: c.exr is one of the parts; write the merge to another file\n");
  EXPECT_EQ(test::readFile(dir_ / "c.exr"), before);
}

// --samples is checked before any work: the range's form, with --spp, on a real-time algorithm.
TEST_F(MergeCli, SamplesFlagIsChecked) {
  for (const char* bad : {"5:5", "7:3", "3", "-1:4", "0:2147483648", "a:b"}) {
    const RunResult r = run(std::string("render fog.json -o x.exr --samples ") + bad);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_EQ(r.err, std::string("narval: --samples: expected A:B, the sample indices [A, B) with 0 <= A < B <= "
                                 "2147483647, got '") +
                         bad + "'\n");
  }
  RunResult r = run("render fog.json -o x.exr --samples 0:4 --algorithm raymarch");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: --samples: does not apply to raymarch, which renders frames (use --frames)\n");
  r = run("render fog.json -o x.exr --samples 0:4 --spp 4");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: --spp excludes --samples (see narval --help)\n");
  EXPECT_FALSE(fs::exists(dir_ / "x.exr"));
  // Resuming a part from another start is refused, the file untouched.
  part("p.exr", 4, 8);
  const std::string before = test::readFile(dir_ / "p.exr");
  r = run("render fog.json -o p.exr --resume --samples 0:8");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: p.exr: narval:sample_begin: holds samples from 4 on, not from 0; resume it with "
                   "--samples 4:END\n");
  EXPECT_EQ(test::readFile(dir_ / "p.exr"), before);
}

}  // namespace
}  // namespace narval
