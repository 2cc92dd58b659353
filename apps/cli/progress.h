// A progress bar with ETA on stderr, shown only on a terminal and only once
// a task has run for more than a second.
#pragma once

#include <chrono>
#include <iosfwd>
#include <string>

namespace pathlab::cli {

class ProgressBar {
 public:
  ProgressBar(std::ostream& err, std::string label, bool enabled);
  ~ProgressBar();
  void update(double fraction);  // 0..1
  void finish();

 private:
  std::ostream& err_;
  std::string label_;
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

// True if stderr is a terminal.
bool stderr_is_terminal();

}  // namespace pathlab::cli
