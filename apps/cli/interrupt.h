// Ctrl-C (SIGINT) and SIGTERM during a render. While an InterruptGuard
// lives, the first such signal is only recorded: the render stops at the
// next whole pass and writes what it has (its checkpoint, the image of the
// passes done). A second one ends the process at once, as without the guard;
// the last checkpoint written stays whole (it is replaced atomically).
#pragma once

namespace pathlab::cli {

class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  // The signal received since the guard was made (SIGINT or SIGTERM), or 0.
  static int received();
};

}  // namespace pathlab::cli
