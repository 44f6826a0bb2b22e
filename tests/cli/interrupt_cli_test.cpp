// Ctrl-C and --resume (issue 5): SIGINT during a render writes the samples done so far as a valid
// EXR (spp in its header and in --stats-json) and exits 130; --resume continues it, and the pixels
// equal those of one uninterrupted render with the same seed, bit for bit.
//
// Why bit for bit: sample s of pixel p depends only on (seed, p, s) (counter-based RNG), and the
// kernel adds each sample exactly to a fixed-point sum (accum.h) that the EXR carries. Integer sums
// do not depend on how the samples were split, into launches or runs.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_fixture.h"
#include "exr_bits.h"
#include "fog_scene.h"
#include "image/image.h"

namespace narval::test {
namespace {

namespace fs = std::filesystem;

class InterruptCli : public CliFixture {
 protected:
  void SetUp() override { write("fog.json", fogSceneJson(24, 16, 1000000)); }

  // Starts `narval ARGS...` in the test folder, sends SIGINT after `delay`, and waits for it.
  RunResult runInterrupted(const std::vector<std::string>& args, std::chrono::milliseconds delay) {
    const std::string outFile = (dir_ / "stdout.txt").string(), errFile = (dir_ / "stderr.txt").string();
    const pid_t pid = fork();
    if (pid == 0) {
      if (chdir(dir_.c_str()) != 0) _exit(127);
      const int out = open(outFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err = open(errFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(out, STDOUT_FILENO);
      dup2(err, STDERR_FILENO);
      std::vector<char*> argv{const_cast<char*>(NARVAL_BINARY)};
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(NARVAL_BINARY, argv.data());
      _exit(127);
    }
    std::this_thread::sleep_for(delay);
    kill(pid, SIGINT);
    int status = 0;
    waitpid(pid, &status, 0);
    RunResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = readFile(outFile);
    r.err = readFile(errFile);
    return r;
  }

  // Interrupts a 10^6-spp render of fog.json into `exr`; the delay doubles until the render had
  // got past its first pass (program build and start-up take a varying time).
  RunResult interruptedRender(const std::string& exr) {
    RunResult r;
    for (int ms = 1500; ms <= 24000; ms *= 2) {
      r = runInterrupted({"render", "fog.json", "-o", exr, "--samples-per-pass", "4", "--stats-json", "stats.json"},
                         std::chrono::milliseconds(ms));
      if (r.err.find("nothing written") == std::string::npos) break;
      EXPECT_EQ(r.code, 130) << r.err;  // interrupted before the first pass: 130 as well
      EXPECT_FALSE(fs::exists(dir_ / exr)) << "nothing may be written before the first pass";
    }
    return r;
  }

  std::string file(const std::string& name) const { return tmp_.file(name); }
};

TEST_F(InterruptCli, SigintWritesTheSamplesDoneAndResumeGivesTheUninterruptedBits) {
  const RunResult cut = interruptedRender("fog.exr");
  ASSERT_EQ(cut.code, 130) << cut.err;
  const auto attrs = readExrAttributes(file("fog.exr"));
  const int k = std::stoi(attrs.at("narval:spp"));
  // Whole passes of 4 samples only, fewer than asked for, at least one pass.
  EXPECT_GT(k, 0);
  EXPECT_LT(k, 1000000);
  EXPECT_EQ(k % 4, 0);
  EXPECT_NE(cut.err.find("narval: interrupted: wrote fog.exr and fog.png with " + std::to_string(k) +
                         " of 1000000 spp; --resume continues it"),
            std::string::npos)
      << cut.err;
  EXPECT_TRUE(fs::exists(dir_ / "fog.png"));
  const nlohmann::json stats = nlohmann::json::parse(readFile(dir_ / "stats.json"));
  EXPECT_EQ(stats["spp"], k);
  EXPECT_EQ(stats["spp_requested"], 1000000);
  EXPECT_EQ(stats["interrupted"], true);

  // The image is the accumulated sum over the k samples, as a finished render's would be: red's
  // 128-bit fixed-point sum (units of 2^-64; words w0..w3, low first) over k, rounded once.
  const ImageRGB cutImage = readExr(file("fog.exr"));
  const std::vector<ExrUintChannel> red =
      readExrUintChannels(file("fog.exr"), {"accum.R.w0", "accum.R.w1", "accum.R.w2", "accum.R.w3"});
  for (size_t i = 0; i < cutImage.rgb.size() / 3; ++i) {
    const uint64_t lo = uint64_t(red[1].values[i]) << 32 | red[0].values[i];
    const uint64_t hi = uint64_t(red[3].values[i]) << 32 | red[2].values[i];
    const double sum = double(int64_t(hi)) + std::ldexp(double(lo), -64);
    ASSERT_EQ(cutImage.rgb[i * 3], float(sum / k)) << i;
  }
  EXPECT_TRUE(std::any_of(red[0].values.begin(), red[0].values.end(), [](uint32_t w) { return w != 0; }))
      << "the low words must be carried, or resuming would not be exact";

  // Resume to k + 13 samples (passes of 4: 4, 4, 4, 1) against one render of k + 13 in passes of 5.
  const std::string total = std::to_string(k + 13);
  const RunResult resumed =
      run("render fog.json -o fog.exr --resume --spp " + total + " --samples-per-pass 4 --stats-json resumed.json");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  const RunResult whole = run("render fog.json -o whole.exr --spp " + total + " --samples-per-pass 5");
  ASSERT_EQ(whole.code, 0) << whole.err;
  const nlohmann::json rs = nlohmann::json::parse(readFile(dir_ / "resumed.json"));
  EXPECT_EQ(rs["resumed_from_spp"], k);
  EXPECT_EQ(rs["spp"], k + 13);
  EXPECT_EQ(rs["interrupted"], false);
  EXPECT_EQ(readExrAttributes(file("fog.exr")).at("narval:spp"), total);
  expectSameBits(file("fog.exr"), file("whole.exr"));
}

TEST_F(InterruptCli, ResumeRefusesAnotherScenesRenderAndLeavesItUntouched) {
  ASSERT_EQ(run("render fog.json -o fog.exr --spp 8").code, 0);
  const std::string before = readFile(dir_ / "fog.exr");
  // Another seed means other samples: continuing would mix two renders.
  const RunResult r = run("render fog.json -o fog.exr --spp 16 --seed 8 --resume");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "narval: fog.exr: narval:render_key: rendered from other settings than fog.json with these options "
            "(renderer.seed is 7 in fog.exr, 8 in the scene); only spp and display settings may change: render to "
            "another file or leave out --resume\n");
  EXPECT_EQ(readFile(dir_ / "fog.exr"), before);
  // Display settings do not change the samples: resuming under another exposure is fine.
  EXPECT_EQ(run("render fog.json -o fog.exr --spp 12 --set renderer.exposure=3 --resume").code, 0);
}

TEST_F(InterruptCli, ResumeToFewerSamplesIsAnErrorAndToAsManyIsNothingToDo) {
  ASSERT_EQ(run("render fog.json -o fog.exr --spp 8").code, 0);
  const std::string before = readFile(dir_ / "fog.exr");
  RunResult r = run("render fog.json -o fog.exr --spp 4 --resume");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: fog.exr: narval:spp: has 8 spp, more than the 4 requested\n");
  r = run("render fog.json -o fog.exr --spp 8 --resume");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "fog.exr already has 8 spp; nothing to render\n");
  EXPECT_EQ(readFile(dir_ / "fog.exr"), before);
}

TEST_F(InterruptCli, ResumeNeedsAPathTracedNarvalRender) {
  ASSERT_EQ(run("render fog.json -o march.exr --algorithm raymarch").code, 0);
  RunResult r = run("render fog.json -o march.exr --spp 8 --resume");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: march.exr: narval:algorithm: rendered by raymarch; only pathtrace renders resume\n");
  r = run("render fog.json -o march.exr --algorithm raymarch --resume");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: --resume: only path-traced renders resume; the algorithm is raymarch\n");
  // An EXR from elsewhere (no narval attributes).
  writeExr(file("plain.exr"), ImageRGB{24, 16, std::vector<float>(24 * 16 * 3, 0.5f)});
  r = run("render fog.json -o plain.exr --spp 8 --resume");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: plain.exr: narval:algorithm: missing: not a resumable narval path-traced render\n");
  // No file yet: --resume starts from the first sample and says so.
  r = run("render fog.json -o new.exr --spp 4 --resume");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "narval: --resume: new.exr does not exist yet; rendering from the first sample\n");
  EXPECT_EQ(readExrAttributes(file("new.exr")).at("narval:spp"), "4");
}

TEST_F(InterruptCli, SigintDuringRealTimeFramesKeepsTheLastWholeFrame) {
  // 10^7 ray-marched frames of this 24x16 fog take most of an hour (10^4 took about 1.5 s, so the
  // render could end before the interrupt); the interrupt arrives after some frames.
  RunResult r;
  for (int ms = 1500; ms <= 24000; ms *= 2) {
    r = runInterrupted({"render", "fog.json", "-o", "rt.exr", "--algorithm", "raymarch", "--frames", "10000000"},
                       std::chrono::milliseconds(ms));
    if (r.err.find("nothing written") == std::string::npos) break;
  }
  EXPECT_EQ(r.code, 130) << r.err;
  const ImageRGB img = readExr(file("rt.exr"));
  EXPECT_EQ(img.width, 24);
  EXPECT_TRUE(std::all_of(img.rgb.begin(), img.rgb.end(), [](float v) { return std::isfinite(v) && v >= 0; }));
  EXPECT_NE(r.err.find(" of 10000000 frames\n"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace narval::test
