// The GTR1 ("Berry") distribution of Burley's clearcoat (Burley 2012 B.2),
// isotropic, gamma = 1, and its sampling in proportion to D(h) cos(theta_h).
//   D(cos_h) = (a^2 - 1) / (pi ln(a^2) (1 + (a^2 - 1) cos_h^2))
// Masking uses Burley's fixed GGX with alpha 0.25 (smithG_GGX).
#pragma once

#include "core/math.h"

namespace pathlab::gtr1 {

// Burley: alpha = mix(0.1, 0.001, clearcoat_gloss).
inline float alpha_from_gloss(float gloss) { return 0.1f + (0.001f - 0.1f) * gloss; }

inline float D(float cos_h, float a) {
  if (cos_h <= 0.0f) return 0.0f;
  const float a2 = a * a;  // a in [0.001, 0.1] (gloss in [0, 1]): a2 < 1, ln(a2) < 0
  // 1 + (a2 - 1) cos^2 written as a2 cos^2 + (1 - cos)(1 + cos): at the
  // peak (cos -> 1) the published form cancels 1 against 1 - a2 and keeps
  // only the float rounding of a2 - 1 (6e-8, 6 % of a2 = 1e-6 at gloss 1:
  // D was 1.3 % low there). 1 - cos is exact near 1.
  const float denom = a2 * cos_h * cos_h + (1.0f - cos_h) * (1.0f + cos_h);
  return (a2 - 1.0f) / (kPi * std::log(a2) * denom);
}

// smithG_GGX(NdotV, alphaG) / (2 NdotV)-style term: 1 / (c + sqrt(a^2 + c^2 - a^2 c^2)),
// finite at c = 0.
inline float g(float c, float a) {
  if (c < 0.0f) return 0.0f;
  const float a2 = a * a;
  return 1.0f / (c + std::sqrt(a2 + c * c - a2 * c * c));
}

// A half vector with density D(h) cos(theta_h).
inline vec3 sample(vec2 u, float a) {
  const float a2 = a * a;
  // cos^2 = (1 - a2^(1-u)) / (1 - a2), in [0, 1]; clamp the rounding.
  const float cos2 = std::clamp((1.0f - std::pow(a2, 1.0f - u.x)) / (1.0f - a2), 0.0f, 1.0f);
  const float cos_h = std::sqrt(cos2);
  const float sin_h = std::sqrt(std::max(0.0f, 1.0f - cos2));
  const float phi = 2.0f * kPi * u.y;
  return vec3(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
}

}  // namespace pathlab::gtr1
