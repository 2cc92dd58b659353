// The GTR1 ("Berry") distribution of Burley's clearcoat (Burley 2012 B.2),
// isotropic, gamma = 1, and its sampling in proportion to D(h) cos(theta_h),
// at width 1: the formulas are core/bsdf/microfacet-inl.h's, called here
// through lane1 (core/bsdf/microfacet.cpp) as the wavefront's lanes call them.
//   D(cos_h) = (a^2 - 1) / (pi ln(a^2) (1 + (a^2 - 1) cos_h^2))
// Masking uses Burley's fixed GGX with alpha 0.25 (smithG_GGX).
#pragma once

#include "core/math.h"

namespace pathlab::gtr1 {

// Burley: alpha = mix(0.1, 0.001, clearcoat_gloss).
inline float alpha_from_gloss(float gloss) { return 0.1f + (0.001f - 0.1f) * gloss; }

// ln(a^2) and log2(a^2), which D and sample need (Closure keeps both per
// material, so that the lanes need no logarithm of their own).
inline float log_alpha2(float a) { return std::log(a * a); }
inline float log2_alpha2(float a) { return std::log2(a * a); }

// D at the unit half vector h (local frame; the closed-form tests read it,
// the model calls microfacet-inl.h).
float D(const vec3& h, float a);

}  // namespace pathlab::gtr1
