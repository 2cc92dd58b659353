// Running the `pathlab` command line in-process, for tests.
#pragma once

#include "apps/cli/cli.h"

#include <sstream>
#include <string>
#include <vector>

namespace pathlab::test {

struct CliResult {
  int code = -1;
  std::string out, err;
};

inline CliResult run_cli(const std::vector<std::string>& args) {
  std::vector<const char*> argv{"pathlab"};
  for (const std::string& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  CliResult r;
  r.code = cli::run(static_cast<int>(argv.size()), argv.data(), out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

}  // namespace pathlab::test
