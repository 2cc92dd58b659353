// How much of each contribution a strategy keeps: the weights both tracers
// apply, in one place so that they cannot drift apart.
//
//   emission found by a ray:  camera ray or impulse 1; cosine, bsdf 1;
//     light 0 (NEE counted it) unless NEE could not pick it (light pdf 0);
//     mis power heuristic; light+bsdf 2 p_b / (p_b + p_l) after BSDF
//     sampling, 0 after light sampling (one-sample balance heuristic, c = 1/2).
//   a light sample (NEE):     light 1; mis power heuristic;
//     light+bsdf 2 p_l / (p_l + p_b).
#pragma once

#include "core/light_bvh.h"
#include "core/math.h"
#include "core/sampling.h"
#include "core/scene.h"
#include "core/surfel.h"

#include <optional>

namespace pathlab {

// How the ray now being traced was chosen at the vertex before it.
struct PreviousVertex {
  // The vertex as light selection saw it (light_query(): position and the
  // normal of its lit side), for the light pdf of the emitter the ray finds.
  LightQuery ref{};
  float pdf = 0.0f;            // solid-angle density of the direction
  bool impulse = true;         // camera ray or impulse: no other way to find the emitter
  bool bsdf_technique = true;  // light+bsdf: that vertex chose BSDF sampling
};

// The weights above and Russian roulette's survival probability are the
// generic functions of core/simd/lanes-inl.h at width 1
// (core/strategy_weights.cpp): the wavefront's lanes run the same source.
float emission_weight(Strategy strategy, const PreviousVertex& prev, float light_pdf);
float light_sample_weight(Strategy strategy, float light_pdf, float bsdf_pdf);

// What a light sample brings if its shadow ray arrives: a delta light's
// f Le / pdf, an area light's f Le (w / pdf), w its light_sample_weight.
Spectrum delta_light_contribution(const Spectrum& f, const Spectrum& Le, float pdf);
Spectrum light_contribution(const Spectrum& f, const Spectrum& Le, float weight, float pdf);

// Russian roulette after a scatter at a vertex past rr_depth (u its
// Dim::Roulette number): the path goes on with probability *survival =
// min(1, the largest component of beta * *weight), so that paths which
// carry little end early; false where it ends; where it goes on, *weight is
// divided by *survival, which keeps the estimate unbiased.
bool survives_roulette(const Spectrum& beta, float u, Spectrum* weight, float* survival);

// The continuation `strategy` samples at s towards wo: cosine-weighted
// (Surfel::scatter_cosine) for every surface but a pure impulse under
// `cosine`, the BSDF's own sampling (Surfel::scatter) otherwise. *cosine,
// when asked for, says which (the observers report it).
inline std::optional<BsdfSample> scatter_for(Strategy strategy, const Surfel& s, const vec3& wo, float u_lobe, vec2 u_dir,
                                             bool* cosine = nullptr) {
  const bool by_cosine = strategy == Strategy::Cosine && !s.material->is_pure_impulse();
  if (cosine) *cosine = by_cosine;
  return by_cosine ? s.scatter_cosine(wo, u_dir) : s.scatter(wo, u_lobe, u_dir);
}

// A vertex's number drawn only when asked (a callable returning float),
// passed to the functions below without a copy or an allocation; it refers
// to the callable, which must outlive the call (a lambda written in the
// call's arguments does).
class LazyDraw {
 public:
  template <class Draw>
  LazyDraw(const Draw& draw)  // NOLINT(google-explicit-constructor): a lambda converts where it is passed
      : draw_(&draw), call_([](const void* d) { return static_cast<float>((*static_cast<const Draw*>(d))()); }) {}
  float operator()() const { return call_(draw_); }

 private:
  const void* draw_;
  float (*call_)(const void*);
};

// The strategy's dispatch at a vertex (core/simd/lanes-inl.h's generic
// functions at width 1, which the wavefront's lanes call too): whether it
// samples area lights (next-event estimation). u_technique() draws the
// vertex's Dim::Technique number, asked only under light+bsdf, the one
// strategy it decides anything for (under zsobol a draw costs a
// permutation of the Sobol' index).
bool samples_area_lights(Strategy strategy, LazyDraw u_technique);

// The vertex a scatter bs at s (wo towards the previous vertex) leaves for
// the emitter its ray finds, under `strategy`: with whether its
// continuation counts as BSDF sampling (PreviousVertex::bsdf_technique;
// u_technique as above).
PreviousVertex previous_vertex(Strategy strategy, const Surfel& s, const vec3& wo, const BsdfSample& bs,
                               LazyDraw u_technique);

}  // namespace pathlab
