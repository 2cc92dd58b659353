// Energy compensation for the Disney model (DisneyParams::energy_compensation,
// off by default: Burley's published model does not have it).
//
// Burley's lobes are added without accounting for each other: the diffuse
// is not reduced by what the specular layer reflects, the clearcoat sits on
// top of everything, and the diffuse's retro-reflection alone reflects up
// to 1.58 of the light at grazing views. Directional albedo reaches 1.65
// (tests/test_bsdf_stat.cpp prints the worst configuration).
//
// With compensation, the layers are coupled the way a coated surface is
// (the albedo-scaling of Kelemen & Szirmay-Kalos 2001, symmetric so that
// the BRDF stays reciprocal):
//
//   f = f_coat + Tc(mo) Tc(mi) [ f_spec + Ts(mo) Ts(mi) k f_diff ]
//   Tc(m) = 1 - Ec(m),  Ts(m) = 1 - Es(m)   (per channel for Ts)
//   k     = 1 / max(1, max over m of the diffuse family's albedo)
//
// where Ec, Es are the directional albedos of the clearcoat and the
// specular lobe alone, and f_diff is the diffuse family (Disney diffuse,
// subsurface approximation, sheen). Then for every view mo
//   albedo(mo) <= Ec(mo) + Tc(mo) [Es(mo) + Ts(mo) * 1] = 1,
// provided the tables hold upper bounds of Ec and Es. They are tabulated at
// view cosines m_i = (i / (kEnergyTableSize - 1))^2 (dense near grazing,
// where the specular albedo changes fastest); each entry is the largest
// albedo measured over its two neighbouring intervals (so the linear
// interpolant bounds the albedo from above between entries), at azimuths
// 0, 45 and 90 degrees to the tangent for an anisotropic lobe, plus a
// margin kEnergyMargin for the error of the deterministic integration
// (energy.cpp says how each albedo is integrated).
// At normal incidence a smooth dielectric (specular 0.5, Es = 0.04) keeps
// 0.92 of Burley's diffuse; at grazing views the diffuse goes to 0 as the
// specular layer reflects everything.
#pragma once

#include "core/math.h"

#include <array>

namespace pathlab::disney {

struct Closure;

inline constexpr int kEnergyTableSize = 33;
// Added to every albedo the tables hold: 2.5 x the largest error of the
// specular midpoint rule against adaptive quadrature, 1.2e-3, over roughness
// 0.001..1, anisotropy 0 and 0.9 and view cosines 1e-4..1 (clearcoat's:
// 5e-5; the diffuse family's quadrature: ~5e-4 against Monte Carlo).
inline constexpr float kEnergyMargin = 3e-3f;

struct EnergyTables {
  bool on = false;
  std::array<Spectrum, kEnergyTableSize> specular{};  // upper bounds of Es
  std::array<float, kEnergyTableSize> coat{};         // upper bounds of Ec
  Spectrum diffuse_scale{1.0f};                        // k

  // The fraction each layer lets through at view cosine mu, in [0, 1]:
  // linear between the entries at view cosines m_i (core/bsdf/disney-inl.h's
  // specular_transmit and coat_transmit at width 1, as the lanes run them).
  Spectrum specular_transmit(float mu) const;
  float coat_transmit(float mu) const;
};

// The tables for closure `c` (its own `energy` is ignored). Tables are
// computed once per distinct closure and cached (0.05-0.2 s each).
EnergyTables make_energy_tables(const Closure& c);

}  // namespace pathlab::disney
