// child_reader.h: reading a file's contents in a forked child (Linux), for the .vdb reader.
// OpenVDB 10's readers trust the sizes and flags they find in a file. Corrupted bytes inside
// compressed leaf data (a size field larger than its buffer, a wrong mask flag) overflow a heap
// buffer in io::readCompressedValues / io::bloscFromStream: that aborts the process ("double free
// or corruption") or, worse, corrupts the heap silently and crashes it later. A corrupted length
// in the metadata makes it build (and zero) a string of up to 4 GiB. None of this can be caught,
// so every read of a file's contents runs in a forked child that shares nothing with us but a
// memfd: it writes a result record (and the dense values after the first page) there. A child
// that dies on a signal, or runs past a time limit, is reported as a corrupt file. The child runs
// single-threaded (a one-slot TBB arena and a serial copy: the parent's TBB workers do not exist
// in it), writes nothing to our stderr and leaves with _exit. NARVAL_VDB_IN_PROCESS=1 reads in
// this process instead (for debuggers and memory checkers).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include <unistd.h>

#include "volume/vdb_io.h"

namespace narval {

struct ChildRecord {
  uint64_t magic;
  int32_t ok;  // 1: result (Decoded, or names in the data area); 0: InputError message; -1: other error
  uint32_t payloadBytes;  // names: bytes after the first page
  Decoded decoded;
  char message[3072];
};
constexpr uint64_t kRecordMagic = 0x6e617276616c7664ull;  // "narvalvd"
constexpr size_t kDataOffset = 4096;
static_assert(sizeof(ChildRecord) <= kDataOffset, "the record fits in the first page");

struct Fd {
  int fd = -1;
  Fd() = default;
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// Runs `work(fd, record)` in a child; returns false (nothing ran) when no child can be used.
// After a true return `mem` holds what the child wrote and `rec` its record (ok == 1); InputErrors
// from the child, crashes and time-outs are thrown here as "PATH: grid: CANNOT (...)".
bool runInChild(const std::string& path, const std::string& cannot, const std::function<void(int, ChildRecord&)>& work,
                Fd& mem, ChildRecord& rec);

// Runs produce() in a child (runInChild) and passes the text it returns back into *text; false
// when no child can be used. `cannot` words the failures ("cannot list the grids").
bool textInChild(const std::string& path, const std::string& cannot, const std::function<std::string()>& produce,
                 std::string* text);

}  // namespace narval
