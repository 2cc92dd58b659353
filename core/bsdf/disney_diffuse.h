// Burley's diffuse with retro-reflection and the Hanrahan-Krueger-inspired
// subsurface approximation (Burley 2012 5.3, disney.brdf), as f cos(theta_i)
// per unit base colour:
//   Fd   = (1 + (Fd90 - 1) FL)(1 + (Fd90 - 1) FV),    Fd90 = 0.5 + 2 roughness cos_d^2
//   Fss  = (1 + (Fss90 - 1) FL)(1 + (Fss90 - 1) FV),  Fss90 = roughness cos_d^2
//   ss   = 1.25 (Fss (1 / (NL + NV) - 0.5) + 0.5)
//   f    = mix(Fd, ss, subsurface) / pi
// with FL, FV Schlick weights of the light and view cosines and cos_d = L.H.
#pragma once

#include "core/bsdf/fresnel.h"

namespace pathlab::disney_diffuse {

inline float eval_cos(float roughness, float subsurface, float NL, float NV, float LdotH) {
  const float FL = fresnel::schlick_weight(NL), FV = fresnel::schlick_weight(NV);
  const float cd2 = LdotH * LdotH;
  const float fd90 = 0.5f + 2.0f * roughness * cd2;
  const float fd = (1.0f + (fd90 - 1.0f) * FL) * (1.0f + (fd90 - 1.0f) * FV);
  const float fss90 = roughness * cd2;
  const float fss = (1.0f + (fss90 - 1.0f) * FL) * (1.0f + (fss90 - 1.0f) * FV);
  // ss NL with the 1 / (NL + NV) folded into NL / (NL + NV) <= 1: the plain
  // form overflows to infinity when both cosines are tiny (denormal).
  const float sum = NL + NV;
  const float q = sum > 0.0f ? NL / sum : 0.0f;
  const float ss_nl = 1.25f * (fss * (q - 0.5f * NL) + 0.5f * NL);
  return (fd * NL + (ss_nl - fd * NL) * subsurface) * kInvPi;
}

}  // namespace pathlab::disney_diffuse
