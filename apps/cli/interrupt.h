// Ctrl-C (SIGINT) and SIGTERM during a render. While an InterruptGuard
// lives, the first such signal is only recorded: the render stops at the
// next whole pass and writes what it has (its checkpoint, the image of the
// passes done). A second one ends the process at once, as without the guard;
// the last checkpoint written stays whole (it is replaced atomically).
#pragma once

namespace pathlab::cli {

// For the whole process: SIGINT, SIGTERM and SIGHUP remove the temporary
// files of writes in progress (core/temp_files.h) and then end it as they do
// by default. An InterruptGuard replaces this while it lives (and removes
// them on its second signal). Called once by the pathlab binary's run().
void remove_temp_files_on_signals();

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
