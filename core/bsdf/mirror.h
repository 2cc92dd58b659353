// The perfect mirror: a Dirac delta in the reflected direction. It has no
// density a light sample could ever hit, so eval and pdf are 0 for every
// direction and only `scatter` produces it. The formulas are core/bsdf/
// mirror-inl.h's, here at width 1 (the wavefront's lanes call the same);
// include from core's .cpp files only (core/simd/width1.h).
#pragma once

#include "core/bsdf/mirror-inl.h"
#include "core/math.h"
#include "core/simd/width1.h"

namespace pathlab::mirror {

// The reflection of wo_local (wo on +z) about +z, chosen with probability
// *pdf = min(1, mean reflectance) (false: absorbed); *weight = albedo / *pdf.
inline bool sample(const Spectrum& albedo, float u_lobe, const vec3& wo_local, vec3* wi_local, Spectrum* weight,
                   float* pdf) {
  using namespace width1;
  F3 wi, w;
  F p;
  const bool ok = generic::mirror_sample(kScalar, lanes(albedo), F{u_lobe}, lanes(wo_local), wi, w, p).raw;
  *wi_local = scalars(wi);
  *weight = scalars(w);
  *pdf = p.raw;
  return ok;
}

}  // namespace pathlab::mirror
