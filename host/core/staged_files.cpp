#include "core/staged_files.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "core/atomic_file.h"

namespace narval {

namespace fs = std::filesystem;

StagedFiles::~StagedFiles() {
  std::error_code ec;
  for (const auto& [staged, final] : files_) fs::remove(staged, ec);
}

std::string StagedFiles::stage(const std::string& finalPath) {
  const fs::path p(finalPath);
  const std::string name =
      "." + p.stem().string() + ".staged-" + std::to_string(static_cast<long>(::getpid())) + p.extension().string();
  const std::string staged = (p.has_parent_path() ? p.parent_path() / name : fs::path(name)).string();
  files_.emplace_back(staged, finalPath);
  return staged;
}

void StagedFiles::commit() {
  while (!files_.empty()) {
    const auto [staged, final] = files_.front();
    std::error_code ec;
    fs::rename(staged, final, ec);
    if (ec) throw std::runtime_error(writeErrorMessage(final, ec.message()));
    files_.erase(files_.begin());
  }
}

}  // namespace narval
