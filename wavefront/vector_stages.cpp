// The parts of vector_stages.h compiled for the baseline instruction set.
#include "wavefront/vector_stages.h"

#include "core/sampling.h"

namespace pathlab::vector_stages {

bool cpu_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
         __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
}

void concentric_disk(float ux, float uy, float* dx, float* dy) {
  const vec2 d = square_to_concentric_disk(vec2(ux, uy));
  *dx = d.x;
  *dy = d.y;
}

}  // namespace pathlab::vector_stages
