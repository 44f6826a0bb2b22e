#include "viewer/private_xvfb.h"

#include <poll.h>
#include <sys/prctl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <sstream>

#include "core/input_error.h"

namespace narval {

bool xvfbInstalled() {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (!dir.empty() && access((dir + "/Xvfb").c_str(), X_OK) == 0) return true;
  return false;
}

PrivateXvfb::PrivateXvfb(int width, int height) {
  if (!xvfbInstalled())
    throw InputError("view: no display to open a window on (DISPLAY is not set) and no Xvfb to start for a "
                     "headless run (Debian: apt-get install xvfb)");
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("view: cannot start Xvfb: pipe failed");
  const std::string fd = std::to_string(fds[1]);
  const std::string screen = std::to_string(std::max(width, 64)) + "x" + std::to_string(std::max(height, 64)) + "x24";
  pid_ = fork();
  if (pid_ == 0) {
    close(fds[0]);
    // The server goes with the viewer even when the viewer cannot stop it (killed, Ctrl-C).
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    // Its chatter (font paths, keyboard maps) is not the user's business.
    if (freopen("/dev/null", "w", stderr) == nullptr) _exit(127);
    execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", screen.c_str(), "-nolisten", "tcp",
           static_cast<char*>(nullptr));
    _exit(127);
  }
  close(fds[1]);
  if (pid_ < 0) {
    close(fds[0]);
    throw std::runtime_error("view: cannot start Xvfb: fork failed");
  }
  // Xvfb writes the display number and a newline once it accepts connections.
  std::string number;
  pollfd p{fds[0], POLLIN, 0};
  while (number.empty() || number.back() != '\n') {
    if (poll(&p, 1, 10000) <= 0) break;
    char c;
    const ssize_t n = read(fds[0], &c, 1);
    if (n == 1) number += c;
    else if (n == 0 || errno != EINTR) break;
  }
  close(fds[0]);
  if (number.size() < 2 || number.back() != '\n') {
    kill(pid_, SIGTERM);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
    throw InputError("view: no display to open a window on (DISPLAY is not set), and Xvfb did not start");
  }
  number.pop_back();
  display_ = ":" + number;
  setenv("DISPLAY", display_.c_str(), 1);
}

PrivateXvfb::~PrivateXvfb() {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  waitpid(pid_, nullptr, 0);
  unsetenv("DISPLAY");
}

}  // namespace narval
