// The command line's own conventions: numeric flags refused with the scene loader's wording (never
// CLI11's range text), flags that do not apply to the algorithm, --local-size against the device's
// limit, --quiet, --threads and --exposure/--tonemap. Every refusal: one line, exit 2, nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.h"
#include "cli/fog_scene.h"

namespace narval {
namespace {

namespace fs = std::filesystem;

class FlagsCli : public test::CliFixture {
 protected:
  void SetUp() override { write("s.json", test::fogSceneJson(16, 12, 2)); }
  // Runs a command that must be refused: exit 2, exactly `message` on stderr, no output file.
  void expectRefused(const std::string& args, const std::string& message) {
    SCOPED_TRACE(args);
    const test::RunResult r = run(args);
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err, message);
    EXPECT_EQ(outputs({"s.json"}), std::vector<std::string>{});
  }
};

TEST_F(FlagsCli, OutOfRangeValuesReadLikeTheSceneLoader) {
  expectRefused("render s.json --spp 0", "narval: --spp: must be at least 1, got 0\n");
  expectRefused("render s.json --spp 2.5", "narval: --spp: expected an integer, got '2.5'\n");
  expectRefused("render s.json --bounces -1", "narval: --bounces: must be at least 0, got -1\n");
  expectRefused("render s.json --frames 0", "narval: --frames: must be at least 1, got 0\n");
  expectRefused("render s.json --seed 4294967296", "narval: --seed: must be between 0 and 4294967295, got 4294967296\n");
  expectRefused("render s.json --samples-per-pass 0", "narval: --samples-per-pass: must be at least 1, got 0\n");
  expectRefused("render s.json --majorant-resolution -2", "narval: --majorant-resolution: must be at least 0, got -2\n");
  expectRefused("render s.json --write-partial-images 0", "narval: --write-partial-images: must be a finite number greater than 0, got 0\n");
  expectRefused("render s.json --write-partial-images soon",
                "narval: --write-partial-images: expected a number, got 'soon'\n");
  expectRefused("render s.json --threads 0", "narval: --threads: must be between 1 and 4096, got 0\n");
  expectRefused("sweep s.json -o sw --spp 1 --seed -1", "narval: --seed: must be between 0 and 4294967295, got -1\n");
  expectRefused("make-cloud c.vdb --resolution 4", "narval: --resolution: must be between 8 and 2048, got 4\n");
  expectRefused("view s.json --target-ms -5", "narval: --target-ms: must be a finite number greater than 0, got -5\n");
}

// A number beyond an int names the limit (not CLI11's "Could not convert"); a flag the command does
// not take names the one probably meant: a single dash, a prefix, a near miss.
TEST_F(FlagsCli, UnknownFlagsSuggestAndHugeNumbersNameTheLimit) {
  expectRefused("render s.json --spp 1000000000000", "narval: --spp: must be at most 2147483647, got 1000000000000\n");
  expectRefused("render s.json -spp 4", "narval: -spp: unknown flag (did you mean --spp?)\n");
  expectRefused("render s.json --res 16x12", "narval: --res: unknown flag (did you mean --resolution?)\n");
  expectRefused("render s.json --sp 4", "narval: --sp: unknown flag (did you mean --spp?)\n");
  expectRefused("render s.json --exposure -2 --zzz 1", "narval: --zzz: unknown flag (see narval render --help)\n");
  expectRefused("render s.json extra", "narval: The following argument was not expected: extra (see narval --help)\n");
  // A mistyped required flag: named as the typo it is, not as a missing flag.
  expectRefused("farm s.json --tasks 2 --schedular local", "narval: --schedular: unknown flag (did you mean --scheduler?)\n");
}

// --spp has no meaning for the real-time algorithms (one estimate per pixel per frame); --bounces
// has one only for the ray marcher's multiple-scattering cache, whose paths take the scene's bounces.
TEST_F(FlagsCli, SamplesAndBouncesOnlyWhereTheyApply) {
  expectRefused("render s.json --algorithm raymarch --spp 4",
                "narval: --spp: does not apply to raymarch, which renders frames (use --frames)\n");
  expectRefused("render s.json --algorithm lobe --spp 4",
                "narval: --spp: does not apply to lobe, which renders frames (use --frames)\n");
  expectRefused("render s.json --algorithm lobe --bounces 3",
                "narval: --bounces: does not apply to lobe (only the ray marcher's multiple-scattering cache "
                "traces bounces)\n");
  expectRefused("render s.json --algorithm raymarch --bounces 3 --set renderer.raymarch.multipleScattering=none",
                "narval: --bounces: does not apply to raymarch (only the ray marcher's multiple-scattering cache "
                "traces bounces)\n");
  const test::RunResult r = run("render s.json --algorithm raymarch --bounces 3 --set renderer.raymarch.msCache.paths=4 "
                                "--stats-json st.json -o r.exr");  // the cache, by default
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(test::readFile(dir_ / "st.json"))["bounces"], 3);
}

// A work-group larger than the device takes: a line naming the flag and the limit (the device's
// CL_DEVICE_MAX_WORK_GROUP_SIZE, as `narval devices --json` reports it), not CL_INVALID_WORK_GROUP_SIZE.
TEST_F(FlagsCli, LocalSizeIsCheckedAgainstTheDevice) {
  const test::RunResult d = run("devices --json");
  ASSERT_EQ(d.code, 0) << d.err;
  const nlohmann::json device = nlohmann::json::parse(d.out).at(0);
  const long long most = device["max_work_group_size"];
  long long x = 1;
  while (x * x <= most) x *= 2;  // x² > most: too many work-items however the sides are allowed
  const std::string shape = std::to_string(x) + "x" + std::to_string(x);
  expectRefused("render s.json --local-size " + shape, "narval: --local-size: " + shape + " is " +
                                                           std::to_string(x * x) + " work-items; " +
                                                           device["name"].get<std::string>() + " takes at most " +
                                                           std::to_string(most) + " per group\n");
}

// --quiet: nothing on stdout or stderr for a clean render, and the same files as without it.
TEST_F(FlagsCli, QuietPrintsNothingAndWritesTheSame) {
  const test::RunResult loud = run("render s.json -o loud.exr");
  ASSERT_EQ(loud.code, 0) << loud.err;
  EXPECT_NE(loud.out, "");
  const test::RunResult quiet = run("render s.json -o quiet.exr --quiet");
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.out, "");
  EXPECT_EQ(quiet.err, "");
  EXPECT_EQ(test::readFile(dir_ / "quiet.png"), test::readFile(dir_ / "loud.png"));
  // Warnings still reach stderr.
  nlohmann::json scene = nlohmann::json::parse(test::fogSceneJson(16, 12, 2));
  scene["comment"] = "by hand";
  write("w.json", scene.dump());
  const test::RunResult warned = run("render w.json -o w.exr -q");
  EXPECT_EQ(warned.code, 0);
  EXPECT_EQ(warned.out, "");
  EXPECT_EQ(warned.err, "narval: warning: w.json: unknown key comment (ignored)\n");
}

// --exposure and --tonemap are renderer.exposure and renderer.toneMapping: the same PNG as the
// --set overrides, and another PNG than the scene's own settings (exposure 1, no tone mapping).
TEST_F(FlagsCli, ExposureAndTonemapOverrideTheScene) {
  expectRefused("render s.json --tonemap filmic", "narval: --tonemap: filmic not in {none,reinhard,aces}\n");
  ASSERT_EQ(run("render s.json -o scene.exr").code, 0);
  ASSERT_EQ(run("render s.json -o flags.exr --exposure -1.5 --tonemap aces").code, 0);
  ASSERT_EQ(run("render s.json -o set.exr --set renderer.exposure=-1.5 --set renderer.toneMapping=\\\"aces\\\"").code, 0);
  EXPECT_EQ(test::readFile(dir_ / "flags.png"), test::readFile(dir_ / "set.png"));
  EXPECT_NE(test::readFile(dir_ / "flags.png"), test::readFile(dir_ / "scene.png"));
}

// --threads N sets PoCL's worker threads: the CPU device then reports N compute units.
TEST_F(FlagsCli, ThreadsSetsPoclsWorkerCount) {
  const test::RunResult d = run("devices --json --threads 1");
  ASSERT_EQ(d.code, 0) << d.err;
  const nlohmann::json devices = nlohmann::json::parse(d.out);
  bool sawPocl = false;
  for (const nlohmann::json& dev : devices)
    if (dev["platform"].get<std::string>().find("Portable Computing Language") != std::string::npos &&
        dev["type"] == "CPU") {
      sawPocl = true;
      EXPECT_EQ(dev["compute_units"], 1);
    }
  if (!sawPocl) GTEST_SKIP() << "no PoCL CPU device: --threads has nothing to set";
}

}  // namespace
}  // namespace narval
