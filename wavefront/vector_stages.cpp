// The parts of vector_stages.h compiled for the baseline instruction set.
#include "wavefront/vector_stages.h"

namespace pathlab::vector_stages {

bool cpu_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
         __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
}

}  // namespace pathlab::vector_stages
