// Fresnel terms, in the local shading frame.
//   schlick_weight(c)   (1 - c)^5, Schlick's interpolation weight
//   schlick(F0, c)      F0 + (1 - F0) (1 - c)^5
//   dielectric(c, eta)  exact unpolarised reflectance of a smooth interface,
//                       eta = n_transmitted / n_incident, c = cos of the
//                       incident angle (>= 0); 1 under total internal reflection
#pragma once

#include "core/math.h"

namespace pathlab::fresnel {

// c is a dot product of unit vectors and can round a hair above 1 (or, for
// a denormal input, below 0): 1 - c is clamped so that the weight stays in
// [0, 1] (core/bsdf/disney-inl.h's schlick_weight at width 1).
float schlick_weight(float c);

inline Spectrum schlick(const Spectrum& f0, float c) { return glm::mix(f0, Spectrum(1.0f), schlick_weight(c)); }
inline float schlick(float f0, float c) { return f0 + (1.0f - f0) * schlick_weight(c); }

// Unpolarised Fresnel reflectance of a smooth dielectric interface
// (core/bsdf/fresnel.cpp: the generic fresnel_dielectric of
// core/bsdf/dielectric-inl.h at width 1, as the wavefront's lanes run it).
float dielectric(float cos_i, float eta);

}  // namespace pathlab::fresnel
