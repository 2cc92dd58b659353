// Running pathlab's binary (or mpirun) as a child process, and reading back
// the bits of the images it wrote, for tests of whole runs: kills, signals,
// MPI jobs.
#pragma once

#include "core/image_io.h"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

namespace pathlab::test {

// Runs `program args...` and returns its exit status (128 + the signal if
// one ended it). With `signal` != 0 it is sent that signal `delay` after it
// starts - or after `wait_for` exists, if given (then the process's own
// status if it ends before that).
inline int run_process(const std::string& program, const std::vector<std::string>& args, int signal = 0,
                       std::chrono::milliseconds delay = {}, const std::filesystem::path& wait_for = {}) {
  const auto status_code = [](int status) { return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status); };
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv{const_cast<char*>(program.c_str())};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(program.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  if (signal != 0) {
    while (!wait_for.empty() && !std::filesystem::exists(wait_for)) {
      if (::waitpid(pid, &status, WNOHANG) == pid) return status_code(status);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    std::this_thread::sleep_for(delay);
    ::kill(pid, signal);
  }
  ::waitpid(pid, &status, 0);
  return status_code(status);
}

// An image's pixels as floats, R G B, row by row: compared with ==, bit for bit.
inline std::vector<float> pixel_floats(const std::filesystem::path& exr) {
  const Image image = read_image(exr);
  std::vector<float> out;
  for (const vec3& p : image.pixels) out.insert(out.end(), {p.x, p.y, p.z});
  return out;
}

}  // namespace pathlab::test
