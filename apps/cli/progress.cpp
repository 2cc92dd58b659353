#include "apps/cli/progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <ostream>

namespace pathlab::cli {

bool stderr_is_terminal() { return isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(std::ostream& err, std::string label, bool enabled)
    : err_(err), label_(std::move(label)), enabled_(enabled), start_(std::chrono::steady_clock::now()), last_(start_) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(double fraction) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < 1.0 || now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  shown_ = true;
  constexpr int kWidth = 40;
  const int filled = static_cast<int>(std::lround(fraction * kWidth));
  const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  char line[160];
  std::snprintf(line, sizeof line, "\r%s [%-*s] %5.1f%%  %.0fs elapsed, ETA %.0fs ", label_.c_str(), kWidth,
                std::string(static_cast<std::size_t>(filled), '=').c_str(), 100.0 * fraction, elapsed, eta);
  err_ << line << std::flush;
}

void ProgressBar::finish() {
  if (shown_) err_ << "\r" << std::string(100, ' ') << "\r" << std::flush;
  shown_ = false;
}

}  // namespace pathlab::cli
