// atomic_file.cpp: temporary file + rename (see atomic_file.h).
#include "core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <system_error>

namespace narval {

std::string writeErrorMessage(const std::string& path, const std::string& reason) {
  std::string r = reason;
  for (char& c : r)
    if (c == '\n' || c == '\r') c = ' ';
  return path + ": cannot write: " + r;
}

AtomicFile::AtomicFile(const std::string& path) : path_(path) {
  if (path.empty()) throw std::runtime_error("cannot write a file with an empty name");
  std::random_device device;
  std::mt19937_64 rng((uint64_t(device()) << 32) ^ device() ^ uint64_t(::getpid()));
  static const char hex[] = "0123456789abcdef";
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string candidate = path + ".tmp-";
    uint64_t bits = rng();
    for (int i = 0; i < 6; ++i, bits >>= 4) candidate += hex[bits & 15];
    const int fd = ::open(candidate.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
      if (errno == EEXIST) continue;
      throw std::runtime_error(writeErrorMessage(path_, std::strerror(errno)));
    }
    file_ = ::fdopen(fd, "wb");
    if (!file_) {
      const int err = errno;
      ::close(fd);
      ::unlink(candidate.c_str());
      throw std::runtime_error(writeErrorMessage(path_, std::strerror(err)));
    }
    temp_ = candidate;
    return;
  }
  throw std::runtime_error(writeErrorMessage(path_, "could not create a unique temporary file"));
}

AtomicFile::~AtomicFile() { discard(); }

void AtomicFile::discard() {
  if (file_) {
    std::fclose(file_);
    file_ = nullptr;
  }
  if (!temp_.empty()) {
    ::unlink(temp_.c_str());
    temp_.clear();
  }
}

void AtomicFile::fail(const std::string& reason) {
  discard();
  throw std::runtime_error(writeErrorMessage(path_, reason));
}

void AtomicFile::commit() {
  if (!file_) fail("file already closed");
  errno = 0;
  if (std::fflush(file_) != 0 || std::ferror(file_)) {
    const int err = errno ? errno : EIO;  // ferror() alone: an earlier fwrite failed
    fail(std::strerror(err));
  }
  if (::fsync(::fileno(file_)) != 0 && errno != EINVAL && errno != EROFS) {
    const int err = errno;  // EINVAL/EROFS: a file system that cannot sync; not an error here
    fail(std::strerror(err));
  }
  FILE* f = file_;
  file_ = nullptr;
  if (std::fclose(f) != 0) {
    const int err = errno;
    fail(std::strerror(err));
  }
  std::error_code ec;
  std::filesystem::rename(temp_, path_, ec);
  if (ec) fail(ec.message());
  temp_.clear();
}

void writeTextAtomic(const std::string& path, const std::string& text) {
  AtomicFile f(path);
  if (std::fwrite(text.data(), 1, text.size(), f.file()) != text.size()) f.fail("short write");
  f.commit();
}

void writeAtomically(const std::string& path, const std::function<void(const std::string& tempPath)>& write) {
  AtomicFile f(path);
  try {
    write(f.tempPath());
  } catch (const std::exception& e) {
    f.fail(e.what());
  }
  f.commit();
}

}  // namespace narval
