// The processor a benchmark ran on, for its record: rates and ratios
// measured on one core generation do not carry over to another
// (docs/performance.md). A virtual machine's brand string is often generic,
// hence the family and model numbers.
#pragma once

#include <string>

namespace pathlab::bench {

// "AMD EPYC (family 26, model 2, AVX-512 yes)".
std::string processor();

}  // namespace pathlab::bench
