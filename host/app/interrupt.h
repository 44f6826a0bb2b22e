// interrupt.h: Ctrl-C ends a long render early without losing it. While an
// InterruptWatch lives, the first SIGINT sets flag() (the render stops after the pass in flight
// and writes the samples done; the command exits 130); the handler then returns to the default,
// so a second Ctrl-C ends the process at once, and an atomic write never leaves a broken file.
#pragma once

#include <atomic>

namespace narval {

class InterruptWatch {
 public:
  InterruptWatch();
  ~InterruptWatch();
  InterruptWatch(const InterruptWatch&) = delete;
  InterruptWatch& operator=(const InterruptWatch&) = delete;
  const std::atomic<bool>& flag() const;
};

// Exit status of a command stopped by SIGINT (128 + 2, as shells report it).
constexpr int kExitInterrupted = 130;

}  // namespace narval
