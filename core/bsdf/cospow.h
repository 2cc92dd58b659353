// The cosine-power (Phong) lobe about an axis r: the analytic approximation
// of a microfacet lobe from the course notes. Density in solid angle
//   p(wi) = (n + 1) / (2 pi) cos^n(angle between wi and r),  on the half of
// the sphere around r (directions more than 90 degrees from r: 0).
// The exponent comes from the microfacet alpha by Walter et al.'s
// Beckmann-Phong correspondence n = 2 / alpha^2 - 2.
#pragma once

#include "core/math.h"

namespace pathlab::cospow {

// Capped at 1e6 (alpha ~ 1.4e-3): far narrower lobes only lose float
// precision in the direction (cos = 1 - 5e-7 is 8 ulps from 1).
inline constexpr float kMaxExponent = 1e6f;
inline float exponent_from_alpha(float alpha) {
  return std::clamp(2.0f / (alpha * alpha) - 2.0f, 0.0f, kMaxExponent);
}

// Local frame about r (unit).
inline vec3 sample(const vec3& r, float n, vec2 u) {
  // cos = u^(1/(n+1)), but through 1 - cos = -expm1(ln(u) / (n+1)): at
  // n = 1e6 cos itself is within 1e-6 of 1, where floats are 6e-8 apart, so
  // the angles would come out quantised (and exactly 0 for most u).
  const float one_minus_c = u.x > 0.0f ? -std::expm1(std::log(u.x) / (n + 1.0f)) : 1.0f;  // u = 0: the rim
  const float c = 1.0f - one_minus_c;
  const float s = std::sqrt(std::max(0.0f, one_minus_c * (2.0f - one_minus_c)));
  const float phi = 2.0f * kPi * u.y;
  const Frame f(r);
  return glm::normalize(f.to_world(vec3(s * std::cos(phi), s * std::sin(phi), c)));
}

inline float pdf(const vec3& r, float n, const vec3& wi) {
  // 1 - cos through the chord (|wi - r|^2 / 2): a dot product near 1 loses
  // all the digits that cos^1e6 depends on.
  const vec3 d = wi - r;
  const double one_minus_c = 0.5 * static_cast<double>(glm::dot(d, d));
  if (one_minus_c >= 1.0) return 0.0f;
  return static_cast<float>((n + 1.0) * (1.0 / (2.0 * 3.14159265358979323846)) *
                            std::exp(static_cast<double>(n) * std::log1p(-one_minus_c)));
}

}  // namespace pathlab::cospow
