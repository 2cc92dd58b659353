// The anisotropic GGX distribution of the Disney model's specular lobe, at
// width 1: the formulas are core/bsdf/microfacet-inl.h's (which says what
// they are), called here through lane1 (core/bsdf/microfacet.cpp) as the
// wavefront's lanes call them. Local frame: z = the normal, x/y = the
// tangent directions of alpha_x/y.
#pragma once

#include "core/math.h"

namespace pathlab::microfacet {

// Burley's remapping: alpha = roughness^2, stretched by the anisotropy.
// The floor 1e-3 (Burley's) keeps D below 1/(pi 1e-6) ~ 3.2e5, well inside
// the float range, for roughness 0 and for denormal roughness.
inline constexpr float kMinAlpha = 1e-3f;
inline vec2 alpha_from(float roughness, float anisotropic) {
  const float aspect = std::sqrt(1.0f - 0.9f * anisotropic);
  const float a = roughness * roughness;
  return vec2(std::max(kMinAlpha, a / aspect), std::max(kMinAlpha, a * aspect));
}

// GGX's D(h) (the closed-form tests read it; the model calls microfacet-inl.h).
struct Ggx {
  float ax, ay;
  float D(const vec3& h) const;
};

// Mirror reflection of wo about the unit normal h.
vec3 reflect(const vec3& wo, const vec3& h);

}  // namespace pathlab::microfacet
