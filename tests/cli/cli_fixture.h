// cli_fixture.h: runs the narval binary the way a user does, each test in a fresh folder of its own.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "test_support.h"

namespace narval::test {

struct RunResult {
  int code = -1;
  std::string out, err;
};

class CliFixture : public ::testing::Test {
 protected:
  // Runs `narval ARGS` in the test's folder (after `launcher`, e.g. "xvfb-run -a", when given);
  // stdout and stderr captured to files.
  RunResult run(const std::string& args, const std::string& launcher = "") {
    return runCommand(launcher + " '" + std::string(NARVAL_BINARY) + "' " + args);
  }
  // Runs a shell command line in the test's folder, output captured as run() does.
  RunResult runCommand(const std::string& command) {
    namespace fs = std::filesystem;
    const std::string cmd = "cd '" + dir_.string() + "' && " + command + " > stdout.txt 2> stderr.txt";
    const int status = std::system(cmd.c_str());
    RunResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = readFile(dir_ / "stdout.txt");
    r.err = readFile(dir_ / "stderr.txt");
    fs::remove(dir_ / "stdout.txt");
    fs::remove(dir_ / "stderr.txt");
    return r;
  }
  void write(const std::string& name, const std::string& text) { writeFile(dir_ / name, text); }
  // Files in the folder other than the inputs the test wrote.
  std::vector<std::string> outputs(const std::vector<std::string>& inputs) {
    std::vector<std::string> found;
    for (const std::string& n : tmp_.entries())
      if (std::find(inputs.begin(), inputs.end(), n) == inputs.end()) found.push_back(n);
    return found;
  }
  TempDir tmp_{"narval_cli"};
  const std::filesystem::path dir_ = tmp_.path();
};

}  // namespace narval::test
