// staged_files.h: several output files written as one commit. Each is written (atomically, by the
// usual writers) to a staging name beside its final path; commit() renames them all into place
// only once every one was written. Until then, and if anything fails or throws on the way, every
// final path keeps what it had (an old EXR is never left beside a new stats file, or the reverse)
// and the staged files are removed.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace narval {

class StagedFiles {
 public:
  StagedFiles() = default;
  ~StagedFiles();
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;

  // The path to write `finalPath`'s content to: ".NAME.staged-PID.EXT" in the same folder (so the
  // rename stays on one file system; the extension kept for writers that look at it).
  std::string stage(const std::string& finalPath);
  // Renames every staged file over its final path; std::runtime_error "PATH: cannot write: REASON"
  // if a staged file is missing or a rename fails (the ones not yet renamed are removed).
  void commit();

 private:
  std::vector<std::pair<std::string, std::string>> files_;  // (staged, final)
};

}  // namespace narval
