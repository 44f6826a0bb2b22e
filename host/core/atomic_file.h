// atomic_file.h: write a file so that readers see either the old file or the complete new one.
// Data goes to PATH.tmp-XXXXXX beside PATH (same directory, so same file system), is flushed,
// fsync'ed and closed with every error checked, then renamed over PATH. Until commit() succeeds,
// PATH is untouched; if anything fails (or the AtomicFile is destroyed uncommitted, e.g. during
// stack unwinding) the temporary is removed.
#pragma once

#include <cstdio>
#include <functional>
#include <string>

namespace narval {

class AtomicFile {
 public:
  // Creates the temporary (mode 0666 less the umask, like any new file).
  // Throws std::runtime_error "PATH: cannot write: REASON" when it cannot.
  explicit AtomicFile(const std::string& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  FILE* file() { return file_; }
  const std::string& path() const { return path_; }
  const std::string& tempPath() const { return temp_; }

  // Flushes, syncs, closes and renames over path(); throws std::runtime_error naming path() on
  // any failure, after removing the temporary.
  void commit();
  // Throws std::runtime_error "PATH: cannot write: REASON" (one line) after removing the temporary.
  [[noreturn]] void fail(const std::string& reason);

 private:
  void discard();
  std::string path_, temp_;
  FILE* file_ = nullptr;
};

// "PATH: cannot write: REASON", newlines in REASON folded so the message stays one line.
std::string writeErrorMessage(const std::string& path, const std::string& reason);

// Writes `text` to `path` through an AtomicFile (never a half-written file).
void writeTextAtomic(const std::string& path, const std::string& text);
// The same for a writer that takes a file name (OpenVDB's io::File): `write(tempPath)` fills the
// temporary, which is then committed. Throws std::runtime_error "PATH: cannot write: REASON", the
// writer's exception text as the REASON.
void writeAtomically(const std::string& path, const std::function<void(const std::string& tempPath)>& write);

}  // namespace narval
