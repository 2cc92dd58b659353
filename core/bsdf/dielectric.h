// The smooth dielectric interface: Fresnel reflection and Snell refraction,
// both impulses. Local frame with z = the geometric normal of the FRONT
// (outside) side; a direction with z > 0 is outside. ior = the inside's
// index relative to the outside's. The formulas are core/bsdf/
// dielectric-inl.h's, here at width 1 (the wavefront's lanes call the
// same); include from core's .cpp files only (core/simd/width1.h).
#pragma once

#include "core/bsdf/dielectric-inl.h"
#include "core/material.h"
#include "core/simd/width1.h"

namespace pathlab::dielectric {

struct Sample {
  vec3 wi;          // local
  Spectrum weight;  // f |cos| / pdf
  float pdf;        // the probability of the impulse chosen
  bool transmitted;
};

// Reflect or refract wo_local, chosen by u_lobe in proportion to the energy
// each carries; false where wo grazes exactly or u_lobe falls in the
// absorbed part. `fresnel_ignored`: the test-only fault (surfel.cpp).
inline bool sample(const DielectricParams& glass, float u_lobe, const vec3& wo_local, Sample* out,
                   bool fresnel_ignored = false) {
  using namespace width1;
  F3 wi, weight;
  F pdf;
  lane1::M transmitted{false};
  const bool ok = generic::dielectric_sample(kScalar, F{glass.ior}, lanes(glass.reflectance), lanes(glass.transmittance),
                                             F{u_lobe}, lanes(wo_local), wi, weight, pdf, transmitted, fresnel_ignored)
                      .raw;
  *out = {scalars(wi), scalars(weight), pdf.raw, transmitted.raw};
  return ok;
}

}  // namespace pathlab::dielectric
