#include "app/interrupt.h"

#include <signal.h>
#include <unistd.h>

namespace narval {
namespace {

// Only lock-free atomics may be touched in a signal handler.
static_assert(std::atomic<bool>::is_always_lock_free);
std::atomic<bool> interrupted{false};
struct sigaction previous {};

void onInterrupt(int) {
  interrupted.store(true);
  static const char msg[] =
      "\nnarval: interrupted: finishing the pass in flight, then writing the samples done "
      "(Ctrl-C again quits at once)\n";
  [[maybe_unused]] const ssize_t n = write(STDERR_FILENO, msg, sizeof msg - 1);
}

}  // namespace

InterruptWatch::InterruptWatch() {
  interrupted.store(false);
  struct sigaction sa {};
  sa.sa_handler = onInterrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND | SA_RESTART;  // one-shot: the second Ctrl-C gets the default action
  sigaction(SIGINT, &sa, &previous);
}

InterruptWatch::~InterruptWatch() { sigaction(SIGINT, &previous, nullptr); }

const std::atomic<bool>& InterruptWatch::flag() const { return interrupted; }

}  // namespace narval
