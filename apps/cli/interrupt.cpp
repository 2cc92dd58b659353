#include "apps/cli/interrupt.h"

#include "core/temp_files.h"

#include <atomic>
#include <csignal>

namespace pathlab::cli {
namespace {

std::atomic<int> g_received{0};
static_assert(std::atomic<int>::is_always_lock_free, "read and written from a signal handler");
struct sigaction g_previous_int, g_previous_term;

extern "C" void on_signal(int signal) {
  if (g_received.exchange(signal) != 0) {
    // The second one: do what the signal does by default (end the process),
    // leaving no temporary file of a write in progress.
    remove_registered_temp_files();
    std::signal(signal, SIG_DFL);
    std::raise(signal);
  }
}

// Outside an InterruptGuard: remove the temporary files of writes in
// progress, then end the process as the signal does by default.
extern "C" void on_fatal_signal(int signal) {
  remove_registered_temp_files();
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

}  // namespace

void remove_temp_files_on_signals() {
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction action {};
    action.sa_handler = on_fatal_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    struct sigaction previous {};
    sigaction(s, nullptr, &previous);
    if (previous.sa_handler == SIG_DFL) sigaction(s, &action, nullptr);  // an ignored signal stays ignored
  }
}

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
