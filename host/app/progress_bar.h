// progress_bar.h: a one-line progress bar with ETA on stderr, drawn only when stderr is a terminal.
#pragma once

#include <chrono>
#include <string>

namespace narval {

class ProgressBar {
 public:
  // `enabled` false (--quiet) draws nothing even on a terminal.
  explicit ProgressBar(std::string label, bool enabled = true);
  void update(int done, int total);
  void finish();

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace narval
