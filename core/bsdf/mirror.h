// The perfect mirror: a Dirac delta in the reflected direction. It has no
// density a light sample could ever hit, so eval and pdf are 0 for every
// direction and only `scatter` produces it.
#pragma once

#include "core/math.h"

namespace pathlab::mirror {

// Reflection of `wo` about the +z axis of the local frame.
inline vec3 reflect_local(const vec3& wo_local) { return vec3(-wo_local.x, -wo_local.y, wo_local.z); }

}  // namespace pathlab::mirror
