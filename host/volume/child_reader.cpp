#include "volume/child_reader.h"

#if defined(__linux__)
#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <tbb/task_arena.h>

#include "core/input_error.h"

namespace narval {

bool runInChild(const std::string& path, const std::string& cannot, const std::function<void(int, ChildRecord&)>& work,
                Fd& mem, ChildRecord& rec) {
  if (std::getenv("NARVAL_VDB_IN_PROCESS")) return false;
  mem.fd = ::memfd_create("narval-vdb", MFD_CLOEXEC);
  if (mem.fd < 0) return false;
  const pid_t pid = ::fork();
  if (pid < 0) return false;
  if (pid == 0) {
    struct rlimit noCore{0, 0};
    ::setrlimit(RLIMIT_CORE, &noCore);
    const int devNull = ::open("/dev/null", O_WRONLY);
    if (devNull >= 0) ::dup2(devNull, 2);  // allocator diagnostics are ours to report
    ChildRecord out{};
    out.magic = kRecordMagic;
    try {
      tbb::task_arena arena(1, 1);
      arena.execute([&] { work(mem.fd, out); });
      out.ok = 1;
    } catch (const std::exception& e) {
      out.ok = dynamic_cast<const InputError*>(&e) ? 0 : -1;
      std::snprintf(out.message, sizeof(out.message), "%s", out.ok == 0 ? e.what() : oneLine(e.what()).c_str());
    }
    // The record goes last: a child that dies before this leaves no magic behind.
    if (::pwrite(mem.fd, &out, sizeof(out), 0) != ssize_t(sizeof(out))) ::_exit(3);
    ::_exit(0);
  }

  // A healthy read takes well under a second for these files; the limit is for pathological ones.
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  const double limitS = 120.0 + double(ec ? 0 : size) / 5e6;
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  for (useconds_t nap = 100;; nap = std::min<useconds_t>(nap * 2, 20000)) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) throw inputError(path, "grid", cannot + " (lost the reader process)");
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > limitS) {
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      throw inputError(path, "grid", cannot + " (reading took more than " + std::to_string(int(limitS)) +
                                         " s: the file is probably corrupt)");
    }
    ::usleep(nap);
  }
  if (WIFSIGNALED(status)) {
    throw inputError(path, "grid", cannot + " (the file is corrupt: OpenVDB's reader crashed on it, " +
                                       strsignal(WTERMSIG(status)) + ")");
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
      ::pread(mem.fd, &rec, sizeof(rec), 0) != ssize_t(sizeof(rec)) || rec.magic != kRecordMagic) {
    throw inputError(path, "grid", cannot + " (the reader process failed)");
  }
  rec.message[sizeof(rec.message) - 1] = '\0';
  if (rec.ok == 0) throw InputError(rec.message);
  if (rec.ok != 1) throw inputError(path, "grid", cannot + " (" + rec.message + ")");
  return true;
}

bool textInChild(const std::string& path, const std::string& cannot, const std::function<std::string()>& produce,
                 std::string* text) {
  Fd mem;
  ChildRecord rec{};
  auto work = [&](int fd, ChildRecord& result) {
    const std::string out = produce();
    result.payloadBytes = uint32_t(out.size());
    if (::pwrite(fd, out.data(), out.size(), off_t(kDataOffset)) != ssize_t(out.size())) {
      throw std::runtime_error(cannot + ": cannot pass the result back");
    }
  };
  if (!runInChild(path, cannot, work, mem, rec)) return false;
  text->assign(rec.payloadBytes, '\0');
  if (::pread(mem.fd, text->data(), text->size(), off_t(kDataOffset)) != ssize_t(text->size())) {
    throw inputError(path, "grid", cannot + " (the reader process returned an inconsistent result)");
  }
  return true;
}

}  // namespace narval
#endif
