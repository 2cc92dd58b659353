// The Lambertian lobe, in the local shading frame (z = the normal on the side
// of the outgoing direction). Reflection only: directions below the surface
// get nothing. The formulas are core/bsdf/lambert-inl.h's, here at width 1
// (the wavefront's lanes call the same); include from core's .cpp files only
// (core/simd/width1.h).
#pragma once

#include "core/bsdf/lambert-inl.h"
#include "core/math.h"
#include "core/simd/width1.h"

namespace pathlab::lambert {

// f * cos(theta_i)
inline Spectrum eval(const Spectrum& albedo, const vec3& wi_local) {
  using namespace width1;
  F3 f;
  F pdf;
  generic::lambert_eval(kScalar, lanes(albedo), F{wi_local.z}, f, pdf);
  return scalars(f);
}

inline float pdf(const vec3& wi_local) {
  using namespace width1;
  return generic::cosine_hemisphere_pdf(kScalar, F{wi_local.z}).raw;
}

// Cosine-weighted sampling (weight = f cos / pdf = albedo exactly): false
// where the density is 0 (the disk's rim) or below min_pdf.
inline bool sample(vec2 u, float min_pdf, vec3* wi, float* pdf) {
  using namespace width1;
  F3 w;
  F density;
  const bool ok = generic::lambert_sample(kScalar, F{u.x}, F{u.y}, F{min_pdf}, w, density).raw;
  *wi = scalars(w);
  *pdf = density.raw;
  return ok;
}

}  // namespace pathlab::lambert
