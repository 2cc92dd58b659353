#include "core/ray.h"

#include <algorithm>
#include <cmath>

namespace pathlab {

// core/simd/lanes-inl.h has the same function over vector lanes (the
// wavefront's vectorised stages); VectorStages.* holds the two to the same
// bits. This scalar body stays: the lanes version at width 1 (Highway's
// HWY_SCALAR target, the build's baseline) computes both neighbours of every
// coordinate and takes NaN-aware maxima by branches, and cost 4x this one
// (8.4 % of a zsobol render's samples against 2.0 %, perf).
vec3 offset_ray_origin(const vec3& p, const vec3& error, const vec3& n) {
  float d = glm::dot(glm::abs(n), error);
  // A point with no rounding error across its surface (every vertex on a
  // coordinate plane through the origin: a PLY or glTF ground at y = 0)
  // gets no offset from its bound, and Embree reports hits at t = tnear = 0,
  // so its rays would find the surface again: move it by one float of its
  // largest coordinate (2^-100 at the origin, far above the denormals).
  if (d == 0.0f) d = std::max(std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z))) * 0x1p-23f, 0x1p-100f);
  vec3 offset = d * n;
  vec3 po = p + offset;
  // p + offset is itself rounded: step one more float away from the surface.
  for (int i = 0; i < 3; ++i) {
    if (offset[i] > 0.0f)
      po[i] = next_float_up(po[i]);
    else if (offset[i] < 0.0f)
      po[i] = next_float_down(po[i]);
  }
  return po;
}

}  // namespace pathlab
