// The Disney model's parameters as a scene gives them, and the lobe weights
// and shapes derived from them once per material (the "closure" the
// evaluators in disney.h read). A Lambert material, when the general path
// is forced, is a closure with only a Lambert weight.
#pragma once

#include "core/bsdf/energy.h"
#include "core/bsdf/gtr1.h"
#include "core/bsdf/microfacet.h"
#include "core/math.h"

namespace pathlab {

// Parameters of material type "disney" (ranges and defaults: material.h).
struct DisneyParams {
  Spectrum base_color{0.8f};
  float metallic = 0.0f;
  float subsurface = 0.0f;
  float specular = 0.5f;
  float specular_tint = 0.0f;
  float roughness = 0.5f;
  float anisotropic = 0.0f;
  float sheen = 0.0f;
  float sheen_tint = 0.5f;
  float clearcoat = 0.0f;
  float clearcoat_gloss = 1.0f;
  // Couple the lobes so that no light is created (core/bsdf/energy.h).
  bool energy_compensation = false;
};

namespace disney {

struct Closure {
  Spectrum lambert{0.0f};   // Lambert albedo (0 for a Disney material)
  Spectrum diffuse{0.0f};   // (1 - metallic) base_color
  float roughness = 0.0f;   // for the diffuse retro-reflection
  float subsurface = 0.0f;
  Spectrum sheen{0.0f};     // (1 - metallic) sheen Csheen
  float specular = 0.0f;    // 1 for a Disney material, 0 for a Lambert one
  Spectrum spec0{0.0f};     // Cspec0
  float ax = 1.0f, ay = 1.0f;
  float clearcoat = 0.0f;   // 0.25 clearcoat
  float clearcoat_alpha = 0.1f;
  // ln and log2 of clearcoat_alpha^2, for GTR1's D and its sampling (core/
  // bsdf/microfacet-inl.h): per material, so that no lane needs a logarithm.
  float clearcoat_log_a2 = gtr1::log_alpha2(clearcoat_alpha);
  float clearcoat_log2_a2 = gtr1::log2_alpha2(clearcoat_alpha);
  EnergyTables energy{};    // on: the lobes are coupled (energy.h)
};

// The closure of a Disney material's parameters into *c, every field but
// the energy tables, which it turns off: what make_closure computes, for a
// textured material's hit (evaluate_textured), which has no tables (refused
// at load) and builds its closure in place rather than copying the tables.
inline void set_closure(const DisneyParams& p, Closure* c) {
  const float lum = luminance(p.base_color);
  const Spectrum tint = lum > 0.0f ? p.base_color / lum : Spectrum(1.0f);
  const float dielectric = 1.0f - p.metallic;
  c->lambert = Spectrum(0.0f);
  c->diffuse = dielectric * p.base_color;
  c->roughness = p.roughness;
  c->subsurface = p.subsurface;
  c->sheen = dielectric * p.sheen * glm::mix(Spectrum(1.0f), tint, p.sheen_tint);
  c->specular = 1.0f;
  c->spec0 = glm::mix(p.specular * 0.08f * glm::mix(Spectrum(1.0f), tint, p.specular_tint), p.base_color, p.metallic);
  const vec2 a = microfacet::alpha_from(p.roughness, p.anisotropic);
  c->ax = a.x;
  c->ay = a.y;
  c->clearcoat = 0.25f * p.clearcoat;
  c->clearcoat_alpha = gtr1::alpha_from_gloss(p.clearcoat_gloss);
  c->clearcoat_log_a2 = gtr1::log_alpha2(c->clearcoat_alpha);
  c->clearcoat_log2_a2 = gtr1::log2_alpha2(c->clearcoat_alpha);
  c->energy.on = false;
}

inline Closure make_closure(const DisneyParams& p) {
  Closure c;
  set_closure(p, &c);
  if (p.energy_compensation) c.energy = make_energy_tables(c);
  return c;
}

inline Closure lambert_closure(const Spectrum& albedo) {
  Closure c;
  c.lambert = albedo;
  return c;
}

}  // namespace disney
}  // namespace pathlab
