// Rays and the robust spawning of rays from surfaces.
#pragma once

#include "core/math.h"

namespace pathlab {

struct Ray {
  vec3 origin;
  vec3 dir;           // unit length
  float tmax = kInfinity;
};

// Moves `p` off its surface along `n` (pointing to the side the new ray
// leaves towards) by at least `error`, the bound on how far the computed `p`
// may lie from the true surface, then rounds each coordinate one float further
// away. After this the true surface is strictly behind the ray origin, so the
// ray cannot hit the surface it leaves, however far from the world origin it
// is (Pharr, Jakob, Humphreys, PBR 4th ed., section 6.8.6).
vec3 offset_ray_origin(const vec3& p, const vec3& error, const vec3& n);

}  // namespace pathlab
