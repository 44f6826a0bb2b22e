// process.h: child processes for `narval farm`: scheduler commands (sbatch, openjd) and local tasks.
#pragma once

#include <string>
#include <sys/types.h>
#include <vector>

namespace narval {

// How a child ended: its exit code, or the signal that killed it.
struct ProcessEnd {
  int exitCode = -1;  // -1 when killed by a signal
  int signal = 0;
  bool ok() const { return exitCode == 0; }
  std::string describe() const;  // "exit code 3", "killed by signal 9 (Killed)"
};

// Starts argv[0] (looked up on PATH) with stdout and stderr appended to `logPath` ("" keeps the
// parent's); std::runtime_error naming the program when it cannot be started.
pid_t startProcess(const std::vector<std::string>& argv, const std::string& logPath);
// Waits for a child started by startProcess.
ProcessEnd waitProcess(pid_t pid);
// Waits for any child; *pid receives which one.
ProcessEnd waitAnyProcess(pid_t* pid);
// Runs argv to its end, its stdout into *out (stderr into *err when given, else the parent's).
ProcessEnd runCapturing(const std::vector<std::string>& argv, std::string* out, std::string* err = nullptr);
// Whether `program` is found on PATH (or is an executable path).
bool onPath(const std::string& program);

}  // namespace narval
