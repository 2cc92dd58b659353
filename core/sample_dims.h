// Every random number pathlab draws is u(seed, pixel, sample, bounce, dim):
// this header names every dimension, in one place, so that both tracers draw
// the same number for the same event. Adding a decision to a tracer means
// adding its name here first.
//
// `bounce` is 0 for the camera ray and k >= 1 for the k-th surface vertex of
// the path (the first surface the camera ray hits is vertex 1).
#pragma once

#include <cstdint>

namespace pathlab {

enum class Dim : std::uint32_t {
  // --- bounce 0: the camera -------------------------------------------------
  FilmX = 0,  // position of the sample inside its pixel
  FilmY,
  LensX,      // point on the thin-lens aperture
  LensY,

  // --- bounce k >= 1: one vertex of the path ----------------------------------
  DeltaLightChoice,  // which point light next-event estimation connects to
  LightChoice,       // which area / environment light to sample (by power, or down the light BVH:
                     // one number re-based at each level, core/light_bvh.h)
  LightX,            // point on that light (or direction, for the environment)
  LightY,
  Technique,         // strategy light+bsdf: light sampling or BSDF sampling
  LobeChoice,        // which lobe or impulse of the material scatters
  DirectionX,        // the direction that lobe samples
  DirectionY,
  Roulette,          // Russian roulette survival

  // --- any bounce: the rays that leave it ----------------------------------------
  Alpha,             // the key of every ray leaving this vertex (the camera ray at bounce 0, the
                     // continuation and the shadow rays at k >= 1): stochastic alpha decides each
                     // surface the ray meets by a hash of this key and the surface (core/alpha.h)

  Count
};

}  // namespace pathlab
