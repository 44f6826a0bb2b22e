// `narval farm` as a user runs it, on this machine's processes, on a real one-node Slurm cluster
// (tests/farm/slurm_cluster.sh: slurmctld, slurmd and munge under a temporary folder, its own
// ports, stopped afterwards) and through Open Job Description's own runner (`openjd`, PyPI
// openjd-cli, installed by scripts/test.sh): the merged image is bit for bit one render's; a task
// killed mid-render is reported, nothing is merged, and running the same command again renders
// only that task. Slurm or openjd missing is a skip saying so, and a failure when
// NARVAL_REQUIRE_FARM=1 (CI, where scripts/test.sh installs both).
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <sstream>
#include <string>
#include <thread>

#include "cli/cli_fixture.h"
#include "cli/exr_bits.h"
#include "cli/fog_scene.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

using test::RunResult;

// Skips (or fails under NARVAL_REQUIRE_FARM=1) with `why`.
#define NARVAL_SKIP_WITHOUT_FARM_TOOL(why)                                         \
  do {                                                                             \
    const char* require = std::getenv("NARVAL_REQUIRE_FARM");                      \
    if (require && std::string(require) == "1") FAIL() << (why);                   \
    GTEST_SKIP() << (why);                                                         \
  } while (0)

class FarmCli : public test::CliFixture {
 protected:
  // fog.json at WxH with `spp`, and its single render whole.exr (what every farm must reproduce).
  void scene(int w, int h, int spp) {
    write("fog.json", test::fogSceneJson(w, h, spp));
    const RunResult r = run("render fog.json -o whole.exr -q");
    ASSERT_EQ(r.code, 0) << r.err;
  }
  std::string file(const std::string& name) const { return tmp_.file(name); }
  void expectWhole(const std::string& out) {
    ASSERT_TRUE(fs::exists(dir_ / out)) << out;
    test::expectSameBits(file("whole.exr"), file(out));
  }
  // Runs `farm ARGS` in a thread while SIGKILLing the render of `samples` (e.g. "4:8") once it has
  // run for `after` (and, when `waitFor` names a file, once that file exists); the farm's result.
  RunResult farmKillingTask(const std::string& args, const std::string& samples, std::chrono::milliseconds after,
                            const std::string& waitFor = "") {
    auto farm = std::async(std::launch::async, [&] { return run(args); });
    // A bracket in the regular expression keeps pgrep and pkill from matching their own shell, and
    // the test's folder (in the part's path) from killing another test's render running at once.
    const std::string pattern = "'--samples " + samples.substr(0, 1) + "[" + samples.substr(1, 1) + "]" +
                                samples.substr(2) + " -o " + dir_.string() + "/'";
    bool killed = false;
    for (int i = 0; i < 600 && !killed; ++i) {  // up to a minute for the task to start
      if (std::system(("pgrep -f -- " + pattern + " > /dev/null").c_str()) == 0) {
        std::this_thread::sleep_for(after);
        for (int k = 0; k < 1200 && !waitFor.empty() && !fs::exists(dir_ / waitFor); ++k)
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        killed = std::system(("pkill -KILL -f -- " + pattern).c_str()) == 0;
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
    }
    EXPECT_TRUE(killed) << "the render of samples " << samples << " never ran";
    return farm.get();
  }
};

// Local, 12 spp in 5 tasks, two at a time: each task reported, then the merge; the image is the
// single render's. Without --submit, the job is only written, and its run.sh gives the same bits.
TEST_F(FarmCli, LocalTasksMergeToTheBitsOfOneRender) {
  scene(16, 12, 12);
  RunResult r = run("farm fog.json --tasks 5 --scheduler local -o out.exr --submit --parallel 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.substr(0, r.out.find('\n')),
            "farm: narval-fog, 12 spp in 5 tasks for local: wrote task.sh final.sh run.sh in " + file("out.farm"));
  for (const char* task : {"task 0 samples [0, 2): ", "task 1 samples [2, 4): ", "task 2 samples [4, 7): ",
                           "task 3 samples [7, 9): ", "task 4 samples [9, 12): ", "\nmerge: ",
                           "\nwrote " })
    EXPECT_NE(r.out.find(task), std::string::npos) << task << " in\n" << r.out;
  expectWhole("out.exr");
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(fs::exists(dir_ / ("out.farm/parts/part_" + std::to_string(i) + ".exr")));

  r = run("farm fog.json --tasks 3 --scheduler local -o again.exr");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "farm: narval-fog, 12 spp in 3 tasks for local: wrote task.sh final.sh run.sh in " +
                       file("again.farm") + "\nrun with: sh " + file("again.farm/run.sh") + "\n");
  EXPECT_FALSE(fs::exists(dir_ / "again.exr"));
  r = runCommand("sh again.farm/run.sh");
  ASSERT_EQ(r.code, 0) << r.err;
  expectWhole("again.exr");
}

// Bad input is one line and exit 2, before anything is written.
TEST_F(FarmCli, RefusalsComeBeforeAnyFileIsWritten) {
  write("fog.json", test::fogSceneJson(8, 8, 4));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"farm fog.json --tasks 5 --scheduler local", "narval: --tasks: 5 tasks for 4 spp; a task renders at least one sample\n"},
      {"farm fog.json --tasks 2 --scheduler local --algorithm raymarch", ""},  // not a farm flag: CLI11's message
      {"farm fog.json --tasks 2 --scheduler local --set renderer.algorithm=\\\"lobe\\\"",
       "narval: --scheduler: only path-traced renders split into sample ranges; the algorithm is lobe\n"},
      {"farm fog.json --tasks 2 --scheduler pbs", ""},
      {"farm fog.json --tasks 2 --scheduler local -o out.png", "narval: -o: the output must be an .exr file, got 'out.png'\n"},
      {"farm nothing.json --tasks 2 --scheduler local", "narval: nothing.json: cannot open scene file\n"}};
  for (const auto& [args, line] : cases) {
    const RunResult r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
    if (!line.empty()) EXPECT_EQ(r.err, line) << args;
    EXPECT_EQ(outputs({"fog.json"}), std::vector<std::string>()) << args;
  }
}

// A task SIGKILLed mid-render: reported with its range and log, nothing merged, exit 1. The same
// command again renders only that task and completes the image, the single render's bits.
TEST_F(FarmCli, AKilledTaskIsReportedAndRunningAgainRendersOnlyIt) {
  scene(32, 24, 12000);  // 4000 spp a task: about 1 s here, time to be killed mid-render
  const std::string farm = "farm fog.json --tasks 3 --scheduler local -o out.exr --submit";
  const RunResult r = farmKillingTask(farm, "4000:8000", std::chrono::milliseconds(100));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err, "narval: farm: task 1 samples [4000, 8000) failed: no output written; its log: " +
                       file("out.farm/logs/task_1.log") +
                       "\nnarval: farm: 1 of 3 tasks failed; no merge, " + file("out.exr") +
                       " not written. Run the same command again to run only the missing tasks.\n");
  // The shell running task.sh exits with its child's status: 128 + SIGKILL.
  EXPECT_NE(r.out.find("farm: task 1: exit code 137\n"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
  const RunResult again = run(farm);
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.out.find("farm: 2 of 3 tasks already have their output; running the other 1\n"), std::string::npos)
      << again.out;
  EXPECT_NE(again.out.find("task 0 samples [0, 4000): output from an earlier run\n"), std::string::npos);
  EXPECT_NE(again.out.find("task 2 samples [8000, 12000): output from an earlier run\n"), std::string::npos);
  EXPECT_NE(again.out.find("task 1 samples [4000, 8000): "), std::string::npos);
  expectWhole("out.exr");
}

// --checkpoint: a task killed mid-render has left its part so far (samples [4000, 4000 + k)); the
// same command again continues it (its log says "does not exist yet" once, from the first run
// only) and the image is the single render's bits. A part of another render in the job folder
// (another seed) is not continued but rendered again.
TEST_F(FarmCli, AKilledTaskContinuesFromItsCheckpoint) {
  scene(32, 24, 12000);
  const std::string farm = "farm fog.json --tasks 3 --scheduler local -o out.exr --submit --checkpoint 0.2";
  const RunResult r = farmKillingTask(farm, "4000:8000", std::chrono::milliseconds(100), "out.farm/parts/part_1.exr");
  EXPECT_EQ(r.code, 1) << r.err;
  const auto cut = readExrAttributes(file("out.farm/parts/part_1.exr"));
  EXPECT_EQ(cut.at("narval:sample_begin"), "4000");
  const int end = std::stoi(cut.at("narval:sample_end"));
  EXPECT_GT(end, 4000);
  EXPECT_LT(end, 8000);
  ASSERT_EQ(run("render fog.json --samples 8000:12000 --seed 9 -o out.farm/parts/part_2.exr -q").code, 0);
  const RunResult again = run(farm);
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.out.find("farm: 1 of 3 tasks already have their output; running the other 2\n"), std::string::npos)
      << again.out;
  expectWhole("out.exr");
  const std::string log = test::readFile(dir_ / "out.farm/logs/task_1.log");
  const std::string fresh = "does not exist yet; rendering from the first sample";
  EXPECT_EQ(log.find(fresh), log.rfind(fresh)) << log;
  EXPECT_NE(log.find(fresh), std::string::npos) << log;
}

// A one-node Slurm cluster of this machine: the array tasks and the merge run as Slurm jobs (their
// logs are Slurm's --output files), the image is the single render's; a task killed mid-render
// cancels the merge (afterok), is reported, and submitting again runs only that task.
TEST_F(FarmCli, SlurmRunsTheTasksAsAnArrayAndTheMergeAfterThem) {
  const std::string cluster = std::string(NARVAL_SOURCE_DIR) + "/tests/farm/slurm_cluster.sh";
  const test::TempDir base("narval_slurm");
  const RunResult up = runCommand("bash '" + cluster + "' start '" + base.path().string() + "'");
  if (up.code == 77) NARVAL_SKIP_WITHOUT_FARM_TOOL("no Slurm here: " + up.err);
  struct Stop {
    std::string command;
    ~Stop() { (void)std::system(command.c_str()); }
  } stop{"bash '" + cluster + "' stop '" + base.path().string() + "' > /dev/null 2>&1"};
  ASSERT_EQ(up.code, 0) << up.err << up.out;
  const test::ScopedEnv conf("SLURM_CONF", base.path().string() + "/etc/slurm.conf");

  scene(16, 12, 12);
  RunResult r = run("farm fog.json --tasks 4 --scheduler slurm -o out.exr --submit");
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("; slurm array "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(", final job "), std::string::npos) << r.out;
  expectWhole("out.exr");
  // Slurm wrote the logs (sbatch --output), and the scripts name the array and the dependency.
  EXPECT_TRUE(fs::exists(dir_ / "out.farm/logs/task_3.log"));
  EXPECT_TRUE(fs::exists(dir_ / "out.farm/logs/final.log"));
  EXPECT_NE(test::readFile(dir_ / "out.farm/tasks.sbatch").find("#SBATCH --array=0-3\n"), std::string::npos);
  EXPECT_NE(test::readFile(dir_ / "out.farm/submit.sh").find("--dependency=afterok:$array"), std::string::npos);

  scene(32, 24, 9000);
  const std::string farm = "farm fog.json --tasks 3 --scheduler slurm -o killed.exr --submit";
  r = farmKillingTask(farm, "3000:6000", std::chrono::milliseconds(100));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("narval: farm: task 1 samples [3000, 6000) failed: no output written; its log: " +
                       file("killed.farm/logs/task_1.log")),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "killed.exr"));
  r = run(farm);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("farm: 2 of 3 tasks already have their output; running the other 1\n"), std::string::npos)
      << r.out;
  expectWhole("killed.exr");
}

// The emitted template passes `openjd check`; `openjd run` of it (all steps, in order) gives the
// single render's bits, and so does `narval farm --scheduler openjd --submit`.
TEST_F(FarmCli, OpenJdTemplatePassesCheckAndRunsToTheSameBits) {
  const char* env = std::getenv("NARVAL_OPENJD");
  const std::string openjd = env && *env ? env : "openjd";
  if (runCommand("command -v '" + openjd + "'").code != 0)
    NARVAL_SKIP_WITHOUT_FARM_TOOL("no openjd (pip install openjd-cli; scripts/test.sh installs it into build/)");
  scene(16, 12, 12);
  RunResult r = run("farm fog.json --tasks 3 --scheduler openjd -o out.exr");
  ASSERT_EQ(r.code, 0) << r.err;
  // The command the farm prints, as a user would paste it (its openjd: the one installed here).
  const std::string say = "\nrun with: openjd run " + file("out.farm/template.json") + " -p Scene=" + file("fog.json") +
                          " -p PartsDir=" + file("out.farm/parts") + " -p Output=" + file("out.exr") + "\n";
  ASSERT_NE(r.out.find(say), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir_ / "out.farm/parameter_values.json"));
  r = runCommand("'" + openjd + "' check out.farm/template.json");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_EQ(r.out, "Template at 'out.farm/template.json' passes validation checks.\n");
  r = runCommand("'" + openjd + "'" + say.substr(say.find(" run "), say.size() - say.find(" run ") - 1));
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  expectWhole("out.exr");

  r = runCommand("PATH=\"$(dirname '" + openjd + "'):$PATH\" '" + std::string(NARVAL_BINARY) +
                 "' farm fog.json --tasks 2 --scheduler openjd -o submitted.exr --submit");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  expectWhole("submitted.exr");
}

// The CSV's columns after `seconds` and `speedup` (which are timings): value and the errors.
std::string errorColumns(const std::string& csv) {
  std::string out;
  std::istringstream lines(csv);
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> cells;
    std::istringstream row(line);
    for (std::string c; std::getline(row, c, ',');) cells.push_back(c);
    out += cells.at(0);
    for (size_t i = 3; i < cells.size(); ++i) out += "," + cells[i];
    out += "\n";
  }
  return out;
}

// sweep --scheduler local --submit: one render task per value, then `sweep --collect`: the same
// renders (bit for bit) and the same errors as the sweep run in one process; the OpenJD form of
// the same job (a template with the task commands as an embedded script) passes openjd check and
// runs to the same table. --collect with a render missing names it, exit 2.
TEST_F(FarmCli, SweepAsFarmTasksGivesTheSameRendersAndErrors) {
  write("fog.json", test::fogSceneJson(16, 12, 12));
  RunResult r = run("sweep fog.json --spp 3,6,12 -o plain");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("sweep fog.json --spp 3,6,12 -o farmed --scheduler local --submit");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.substr(0, r.out.find('\n')), "sweep: narval-sweep-fog, 3 renders for local: wrote task.sh final.sh "
                                                 "run.sh in " + file("farmed/farm"));
  EXPECT_NE(r.out.find("task 0 12 spp: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\ncollect: "), std::string::npos) << r.out;
  for (const char* exr : {"spp_00003.exr", "spp_00006.exr", "spp_00012.exr"})
    test::expectSameBits(file(std::string("plain/") + exr), file(std::string("farmed/") + exr), {"R", "G", "B"});
  EXPECT_EQ(errorColumns(test::readFile(dir_ / "farmed/sweep.csv")), errorColumns(test::readFile(dir_ / "plain/sweep.csv")));
  EXPECT_TRUE(fs::exists(dir_ / "farmed/sweep.png"));

  fs::remove(dir_ / "farmed/spp_00006.exr");
  r = run("sweep fog.json --spp 3,6,12 -o farmed --collect");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: farmed/spp_00006.exr: narval:render_key: not a path-traced render of fog.json at 6 spp and "
                   "6 bounces; run the sweep's farm task for it again\n");

  const char* env = std::getenv("NARVAL_OPENJD");
  const std::string openjd = env && *env ? env : "openjd";
  if (runCommand("command -v '" + openjd + "'").code != 0)
    NARVAL_SKIP_WITHOUT_FARM_TOOL("no openjd (pip install openjd-cli; scripts/test.sh installs it into build/)");
  r = run("sweep fog.json --spp 3,6,12 -o oj --scheduler openjd");
  ASSERT_EQ(r.code, 0) << r.err;
  r = runCommand("'" + openjd + "' check oj/farm/template.json");
  EXPECT_EQ(r.code, 0) << r.out;
  r = runCommand("'" + openjd + "' run oj/farm/template.json");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_EQ(errorColumns(test::readFile(dir_ / "oj/sweep.csv")), errorColumns(test::readFile(dir_ / "plain/sweep.csv")));
}

}  // namespace
}  // namespace narval
