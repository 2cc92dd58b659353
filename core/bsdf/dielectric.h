// The smooth dielectric interface: Fresnel reflection and Snell refraction,
// both impulses. Local frame with z = the geometric normal of the FRONT
// (outside) side; a direction with z > 0 is outside. eta = ior of the inside
// relative to the outside.
#pragma once

#include "core/bsdf/fresnel.h"

namespace pathlab::dielectric {

struct Interface {
  float eta_rel;  // n_transmitted / n_incident for light arriving along wo
  float cos_o;    // |wo.z|
  float F;        // Fresnel reflectance (1 under total internal reflection)
};

inline Interface at(const vec3& wo_local, float ior) {
  const bool entering = wo_local.z > 0.0f;
  const float eta_rel = entering ? ior : 1.0f / ior;
  const float cos_o = std::abs(wo_local.z);
  return {eta_rel, cos_o, fresnel::dielectric(cos_o, eta_rel)};
}

inline vec3 reflect(const vec3& wo_local) { return vec3(-wo_local.x, -wo_local.y, wo_local.z); }

// Snell refraction of wo through the interface (assumes no total internal
// reflection, i.e. F < 1).
inline vec3 refract(const vec3& wo_local, const Interface& in) {
  const float sin2_t = (1.0f - in.cos_o * in.cos_o) / (in.eta_rel * in.eta_rel);
  const float cos_t = std::sqrt(std::max(0.0f, 1.0f - sin2_t));  // F < 1 means sin2_t < 1; clamp rounding
  const float side = wo_local.z > 0.0f ? 1.0f : -1.0f;
  const vec3 t = -wo_local / in.eta_rel + vec3(0.0f, 0.0f, side * (in.cos_o / in.eta_rel - cos_t));
  return glm::normalize(t);
}

}  // namespace pathlab::dielectric
