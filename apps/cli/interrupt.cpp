#include "apps/cli/interrupt.h"

#include <atomic>
#include <csignal>

namespace pathlab::cli {
namespace {

std::atomic<int> g_received{0};
static_assert(std::atomic<int>::is_always_lock_free, "read and written from a signal handler");
struct sigaction g_previous_int, g_previous_term;

extern "C" void on_signal(int signal) {
  if (g_received.exchange(signal) != 0) {
    // The second one: do what the signal does by default (end the process).
    std::signal(signal, SIG_DFL);
    std::raise(signal);
  }
}

}  // namespace

InterruptGuard::InterruptGuard() {
  g_received = 0;
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // the render's reads and writes carry on
  sigaction(SIGINT, &action, &g_previous_int);
  sigaction(SIGTERM, &action, &g_previous_term);
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
}

int InterruptGuard::received() { return g_received.load(); }

}  // namespace pathlab::cli
