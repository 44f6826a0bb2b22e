// private_xvfb.h: a virtual X server of the viewer's own, for headless runs (--script, --frames)
// on a machine without a display: Xvfb started on a free display number (it reports the number
// through -displayfd), DISPLAY pointed at it, and the server stopped when this object goes (or,
// should the viewer be killed, by the kernel: PR_SET_PDEATHSIG).
#pragma once

#include <string>
#include <sys/types.h>

namespace narval {

class PrivateXvfb {
 public:
  // Starts `Xvfb -displayfd FD -screen 0 WIDTHxHEIGHTx24 -nolisten tcp` and sets DISPLAY. Throws
  // InputError when Xvfb is not installed or does not start within 10 s.
  PrivateXvfb(int width, int height);
  ~PrivateXvfb();
  PrivateXvfb(const PrivateXvfb&) = delete;
  PrivateXvfb& operator=(const PrivateXvfb&) = delete;
  const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  std::string display_;
};

// Whether an Xvfb executable is on PATH.
bool xvfbInstalled();

}  // namespace narval
