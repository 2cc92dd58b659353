// Errors that reach the user. Library code never exits or prints: it throws
// one of these with a message that names the file, the place and the
// problem, and the CLI turns it into one line on stderr and exit code 2.
#pragma once

#include <stdexcept>
#include <string>

namespace pathlab {

// Bad input: a scene file, a mesh, an image or a command-line value that
// cannot be used. `what()` is the complete, user-facing message.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A failure of the machine or of a library underneath us (Embree device
// error, out of memory, a write that failed half way).
class SystemError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace pathlab
