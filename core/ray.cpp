#include "core/ray.h"

namespace pathlab {

vec3 offset_ray_origin(const vec3& p, const vec3& error, const vec3& n) {
  const float d = glm::dot(glm::abs(n), error);
  vec3 offset = d * n;
  vec3 po = p + offset;
  // p + offset is itself rounded: step one more float away from the surface.
  for (int i = 0; i < 3; ++i) {
    if (offset[i] > 0.0f)
      po[i] = std::nextafter(po[i], kInfinity);
    else if (offset[i] < 0.0f)
      po[i] = std::nextafter(po[i], -kInfinity);
  }
  return po;
}

}  // namespace pathlab
