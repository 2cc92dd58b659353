#include "core/ray.h"

#include "core/simd/width1.h"

namespace pathlab {

// The generic function (core/simd/lanes-inl.h) at width 1: the very code
// the wavefront's lanes run.
vec3 offset_ray_origin(const vec3& p, const vec3& error, const vec3& n) {
  using namespace width1;
  return scalars(generic::offset_ray_origin(kScalar, lanes(p), lanes(error), lanes(n)));
}

}  // namespace pathlab
