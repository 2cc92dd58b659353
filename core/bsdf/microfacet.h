// The anisotropic GGX distribution (GTR2 with gamma = 2, Burley 2012 B.2)
// with separable Smith masking-shadowing, and exact sampling of its visible
// normals (Heitz 2018, "Sampling the GGX Distribution of Visible Normals").
// Local frame: z = the normal, x/y = the tangent directions of alpha_x/y.
//
//   D(h)      = 1 / (pi ax ay (hx^2/ax^2 + hy^2/ay^2 + hz^2)^2)
//   g(w)      = 1 / (wz + sqrt(ax^2 wx^2 + ay^2 wy^2 + wz^2)) = G1(w) / (2 wz)
//               (Burley's smithG_GGX_aniso; finite at wz = 0)
//   G1(w)     = 2 wz g(w)
//   VNDF pdf of the reflected wi:  G1(wo) D(h) / (4 wo.z) = g(wo) D(h) / 2
#pragma once

#include "core/math.h"

namespace pathlab::microfacet {

// Burley's remapping: alpha = roughness^2, stretched by the anisotropy.
// The floor 1e-3 (Burley's) keeps D below 1/(pi 1e-6) ~ 3.2e5, well inside
// the float range, for roughness 0 and for denormal roughness.
inline constexpr float kMinAlpha = 1e-3f;
inline vec2 alpha_from(float roughness, float anisotropic) {
  const float aspect = std::sqrt(1.0f - 0.9f * anisotropic);
  const float a = roughness * roughness;
  return vec2(std::max(kMinAlpha, a / aspect), std::max(kMinAlpha, a * aspect));
}

struct Ggx {
  float ax, ay;

  float D(const vec3& h) const {
    if (h.z <= 0.0f) return 0.0f;
    const float e = sqr(h.x / ax) + sqr(h.y / ay) + h.z * h.z;
    // e >= hz^2 > 0 here unless hz underflows; e is at most ~1e6 (1/alpha^2),
    // so e^2 cannot overflow.
    return e > 0.0f ? 1.0f / (kPi * ax * ay * e * e) : 0.0f;
  }
  float g(const vec3& w) const {
    const float s = std::sqrt(sqr(ax * w.x) + sqr(ay * w.y) + w.z * w.z);
    // s >= min(alpha) |w| > 0 for a unit w, so the division is safe; wz < 0
    // means the direction is below the surface: masked.
    return w.z < 0.0f ? 0.0f : 1.0f / (w.z + s);
  }
  float G1(const vec3& w) const { return 2.0f * w.z * g(w); }

  // A visible normal for wo (wo.z >= 0), from two uniform numbers.
  vec3 sample_visible(const vec3& wo, vec2 u) const {
    // Stretch the view to the hemisphere configuration.
    const vec3 vh = glm::normalize(vec3(ax * wo.x, ay * wo.y, wo.z));
    const float lensq = vh.x * vh.x + vh.y * vh.y;
    const vec3 t1 = lensq > 0.0f ? vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : vec3(1.0f, 0.0f, 0.0f);
    const vec3 t2 = glm::cross(vh, t1);
    // A point on the projected disk, warped onto the visible half.
    const float r = std::sqrt(u.x);
    const float phi = 2.0f * kPi * u.y;
    const float p1 = r * std::cos(phi);
    float p2 = r * std::sin(phi);
    const float s = 0.5f * (1.0f + vh.z);
    // 1 - p1^2 can round below 0 when r rounds to 1: clamp.
    p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
    const vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    // Unstretch; z >= 0 by construction, clamp the rounding.
    return glm::normalize(vec3(ax * nh.x, ay * nh.y, std::max(0.0f, nh.z)));
  }
};

// Mirror reflection of wo about the unit normal h.
inline vec3 reflect(const vec3& wo, const vec3& h) { return 2.0f * glm::dot(wo, h) * h - wo; }

// The half vector of two directions on the same side (z > 0); the zero
// vector if they are opposite (then nothing reflects one into the other).
// Computed in double from the exactly normalised directions. At a grazing
// view (wo.z = 1e-3) the reflected lobe's wi is nearly -wo, and h's tilt
// comes from the difference of their near-unit horizontal components,
// about (wi.z^2 - wo.z^2) / 2 ~ 1e-6. A float direction's length is 1 only
// to ~6e-8, which alone moved that tilt by 1 % of alpha = 1e-3 and 1.6 % of
// the lobe's mass from one chi-square bin to another (test_bsdf_stat.cpp,
// BsdfChi2.FullMaterialAtGrazingView); the sampler (VNDF, reflect) is
// invariant to |wo| and was right.
inline vec3 half_vector(const vec3& wo, const vec3& wi) {
  const dvec3 a(wo), b(wi);
  const double la = glm::dot(a, a), lb = glm::dot(b, b);
  if (!(la > 0.0) || !(lb > 0.0)) return vec3(0.0f);
  const dvec3 h = a / std::sqrt(la) + b / std::sqrt(lb);
  const double len2 = glm::dot(h, h);
  return len2 > 0.0 ? vec3(h / std::sqrt(len2)) : vec3(0.0f);
}

}  // namespace pathlab::microfacet
