#include "farm/process.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace narval {
namespace {

ProcessEnd endOf(int status) {
  ProcessEnd e;
  if (WIFEXITED(status)) e.exitCode = WEXITSTATUS(status);
  else if (WIFSIGNALED(status)) e.signal = WTERMSIG(status);
  return e;
}

// posix_spawnp with stdout (and stderr, or not) redirected to the file descriptors given.
pid_t spawn(const std::vector<std::string>& argv, int outFd, int errFd) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (outFd >= 0) posix_spawn_file_actions_adddup2(&actions, outFd, STDOUT_FILENO);
  if (errFd >= 0) posix_spawn_file_actions_adddup2(&actions, errFd, STDERR_FILENO);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(rc));
  return pid;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

std::string ProcessEnd::describe() const {
  if (exitCode >= 0) return "exit code " + std::to_string(exitCode);
  return "killed by signal " + std::to_string(signal) + " (" + strsignal(signal) + ")";
}

pid_t startProcess(const std::vector<std::string>& argv, const std::string& logPath) {
  int fd = -1;
  if (!logPath.empty()) {
    fd = ::open(logPath.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error("cannot write " + logPath + ": " + std::strerror(errno));
  }
  pid_t pid = -1;
  try {
    pid = spawn(argv, fd, fd);
  } catch (...) {
    if (fd >= 0) ::close(fd);
    throw;
  }
  if (fd >= 0) ::close(fd);
  return pid;
}

ProcessEnd waitProcess(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return ProcessEnd{};
  return endOf(status);
}

ProcessEnd waitAnyProcess(pid_t* pid) {
  int status = 0;
  pid_t p;
  while ((p = ::waitpid(-1, &status, 0)) < 0)
    if (errno != EINTR) {
      *pid = -1;
      return ProcessEnd{};
    }
  *pid = p;
  return endOf(status);
}

ProcessEnd runCapturing(const std::vector<std::string>& argv, std::string* out, std::string* err) {
  // Temporary files rather than pipes: no deadlock however much either stream says.
  char outName[] = "/tmp/narval_outXXXXXX", errName[] = "/tmp/narval_errXXXXXX";
  const int outFd = ::mkstemp(outName);
  const int errFd = err ? ::mkstemp(errName) : -1;
  if (outFd < 0 || (err && errFd < 0)) throw std::runtime_error(std::string("cannot capture output: ") + std::strerror(errno));
  ProcessEnd end;
  try {
    end = waitProcess(spawn(argv, outFd, errFd));
  } catch (...) {
    ::close(outFd);
    ::unlink(outName);
    if (errFd >= 0) ::close(errFd), ::unlink(errName);
    throw;
  }
  ::close(outFd);
  *out = slurp(outName);
  ::unlink(outName);
  if (errFd >= 0) {
    ::close(errFd);
    *err = slurp(errName);
    ::unlink(errName);
  }
  return end;
}

bool onPath(const std::string& program) {
  if (program.find('/') != std::string::npos) return ::access(program.c_str(), X_OK) == 0;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':'))
    if (!dir.empty() && ::access((dir + "/" + program).c_str(), X_OK) == 0) return true;
  return false;
}

}  // namespace narval
