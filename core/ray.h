// Rays and the robust spawning of rays from surfaces.
#pragma once

#include "core/math.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace pathlab {

struct Ray {
  vec3 origin;
  vec3 dir;           // unit length
  float tmax = kInfinity;
  // Decides the surfaces of partial coverage the ray meets (core/alpha.h);
  // Embree carries it in its ray's `id`.
  std::uint32_t alpha_key = 0;
};

// Moves `p` off its surface along `n` (pointing to the side the new ray
// leaves towards) by at least `error`, the bound on how far the computed `p`
// may lie from the true surface, then rounds each coordinate one float further
// away. After this the true surface is strictly behind the ray origin, so the
// ray cannot hit the surface it leaves, however far from the world origin it
// is (Pharr, Jakob, Humphreys, PBR 4th ed., section 6.8.6).
// std::nextafter(v, +inf) and std::nextafter(v, -inf), inline: the libm
// call showed in profiles. They step the bit pattern by one; -0 and +0 both
// step to the smallest denormal of the requested sign; NaN and the infinity
// already in the requested direction come back unchanged.
inline float next_float_up(float v) {
  if (std::isnan(v) || (std::isinf(v) && v > 0.0f)) return v;
  if (v == 0.0f) return std::numeric_limits<float>::denorm_min();
  const auto bits = std::bit_cast<std::uint32_t>(v);
  return std::bit_cast<float>(v > 0.0f ? bits + 1 : bits - 1);
}
inline float next_float_down(float v) {
  if (std::isnan(v) || (std::isinf(v) && v < 0.0f)) return v;
  if (v == 0.0f) return -std::numeric_limits<float>::denorm_min();
  const auto bits = std::bit_cast<std::uint32_t>(v);
  return std::bit_cast<float>(v > 0.0f ? bits - 1 : bits + 1);
}

vec3 offset_ray_origin(const vec3& p, const vec3& error, const vec3& n);

}  // namespace pathlab
