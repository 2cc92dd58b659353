// Burley's sheen (2012 5.3): a grazing retro-reflective tint for cloth,
//   f = sheen Csheen FH,   FH = (1 - L.H)^5,  Csheen = mix(1, tint colour, sheen_tint)
// (no 1/pi, as published). Returned as f cos(theta_i) per unit colour.
#pragma once

#include "core/bsdf/fresnel.h"

namespace pathlab::sheen {

inline float eval_cos(float NL, float LdotH) { return fresnel::schlick_weight(LdotH) * NL; }

}  // namespace pathlab::sheen
