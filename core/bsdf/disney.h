// Burley's "principled" BRDF (Burley 2012, "Physically-Based Shading at
// Disney", and its reference disney.brdf), composed from the lobes of this
// folder: Disney diffuse with the subsurface approximation and sheen
// (disney-inl.h), anisotropic GGX with separable Smith masking-shadowing
// (microfacet-inl.h) and Schlick Fresnel, and the GTR1 clearcoat
// (microfacet-inl.h). The formulas are written once over Highway's vectors
// in disney-inl.h and microfacet-inl.h: disney.cpp calls them at width 1,
// the wavefront's lanes at their SIMD width.
//
//   f = (1 - metallic) (Cd mix(Fd, ss, subsurface) / pi + sheen Csheen FH)
//     + D_GTR2 F_s G_s / (4 NL NV)        F_s = mix(Cspec0, 1, FH)
//     + 0.25 clearcoat D_GTR1 F_r G_r / (4 NL NV)    F_r = mix(0.04, 1, FH)
//   Cspec0 = mix(0.08 specular mix(1, Ctint, specular_tint), Cd, metallic)
// With energy_compensation the lobes are coupled as a coated surface's
// (energy.h): the diffuse family is scaled by k Ts(NV) Ts(NL) and
// everything under the clearcoat by Tc(NV) Tc(NL).
//
// Everything works in the local shading frame with wo on the +z side (the
// Surfel flips the frame; the BRDF is two-sided) and returns f cos(theta_i).
//
// Sampling (the pdf is always that of the mixture actually drawn from; a
// sample's weight is the true f cos / pdf):
//   the diffuse lobes (Lambert, Disney diffuse, sheen): cosine-weighted;
//   specular: BsdfSampling::Vndf samples GGX's visible normals exactly,
//             BsdfSampling::Cospow a cosine-power lobe about the mirror
//             direction with exponent 2/alpha^2 - 2 (alpha = sqrt(ax ay)),
//             always mixed with at least 5 % of the cosine lobe (even for a
//             metal) so that f cos / pdf stays bounded;
//   clearcoat: Vndf draws GTR1 half vectors in proportion to D cos,
//             Cospow a cosine-power lobe from the clearcoat alpha;
// with each lobe chosen in proportion to its estimated energy (Schlick at
// the view angle times the lobe's colour, see lobe_probabilities).
#pragma once

#include "core/bsdf/closure.h"
#include "core/material.h"
#include "core/math.h"

#include <array>
#include <optional>

namespace pathlab::disney {

using Params = DisneyParams;

// Feature sets the code is compiled for ("model only what a scene requires").
enum Features : unsigned {
  kDisneyLobes = 1u,  // Disney diffuse, sheen, GGX specular
  kClearcoat = 2u,    // GTR1
  kLambertLobe = 4u,  // a Lambert lobe inside the closure (the general path)
  kGeneral = kDisneyLobes | kClearcoat | kLambertLobe,
};

// The sampled lobe families, in the order of lobe_probabilities().
enum class SampledLobe : std::uint8_t { Diffuse, Specular, Clearcoat, Count };
using LobeProbabilities = std::array<float, 3>;

// f cos(theta_i); wo.z > 0 expected (0 otherwise), 0 for wi below.
template <unsigned F> Spectrum eval(const Closure& c, const vec3& wo, const vec3& wi);
// Solid-angle density of sample<F>(c, wo, ...) at wi.
template <unsigned F> float pdf(const Closure& c, const vec3& wo, const vec3& wi, BsdfSampling sampling);
struct DirectionSample {
  vec3 wi;
  Lobe lobe;
};
// A direction from the mixture; nothing if the drawn direction falls below
// the surface (it has f = 0; the pdf counts that mass as lost).
template <unsigned F>
std::optional<DirectionSample> sample(const Closure& c, const vec3& wo, float u_lobe, vec2 u, BsdfSampling sampling);

// Surfel::scatter's draw (wo on +z): a direction from the mixture,
// weighted by f cos over the mixture's density there, whatever lobe drew
// it; nothing where none was drawn or the density is below min_pdf
// (disney-inl.h's disney_scatter, which the wavefront's lanes call too).
struct Scatter {
  vec3 wi;
  Spectrum weight;
  float pdf;
  Lobe lobe;
};
template <unsigned F>
std::optional<Scatter> scatter(const Closure& c, const vec3& wo, float u_lobe, vec2 u, BsdfSampling sampling,
                               float min_pdf);

LobeProbabilities lobe_probabilities(const Closure& c, const vec3& wo, unsigned features, BsdfSampling sampling);

// One lobe family alone (the per-lobe chi-square tests; the energy tables).
// eval is f cos of that family only, as Burley defines it: without the
// coupling of energy compensation.
Spectrum lobe_eval(const Closure& c, SampledLobe lobe, const vec3& wo, const vec3& wi);
float lobe_pdf(const Closure& c, SampledLobe lobe, const vec3& wo, const vec3& wi, BsdfSampling sampling);
std::optional<vec3> lobe_sample(const Closure& c, SampledLobe lobe, const vec3& wo, vec2 u, BsdfSampling sampling);

}  // namespace pathlab::disney
