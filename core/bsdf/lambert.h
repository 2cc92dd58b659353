// The Lambertian lobe, in the local shading frame (z = the normal on the side
// of the outgoing direction). Reflection only: directions below the surface
// get nothing.
#pragma once

#include "core/math.h"
#include "core/sampling.h"

namespace pathlab::lambert {

// f * cos(theta_i)
inline Spectrum eval(const Spectrum& albedo, const vec3& wi_local) {
  return wi_local.z > 0.0f ? albedo * (wi_local.z * kInvPi) : Spectrum(0.0f);
}

inline float pdf(const vec3& wi_local) { return cosine_hemisphere_pdf(wi_local); }

// Cosine-weighted sampling: weight = f cos / pdf = albedo exactly.
inline vec3 sample(vec2 u) { return square_to_cosine_hemisphere(u); }

}  // namespace pathlab::lambert
