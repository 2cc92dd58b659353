// The `pathlab` command line. Each subcommand lives in its own file; main()
// only calls run(). Exit codes: 0 success, 1 a check failed, 2 bad input or
// usage, 3 a system failure (Embree, out of memory). Human output goes to stderr, machine output (--json) to stdout.
#pragma once

#include <iosfwd>

namespace pathlab::cli {

int run(int argc, const char* const* argv);
// The same, with explicit streams (tests capture them).
int run(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace pathlab::cli
