#include "core/ray.h"

namespace pathlab {

vec3 offset_ray_origin(const vec3& p, const vec3& error, const vec3& n) {
  const float d = glm::dot(glm::abs(n), error);
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
