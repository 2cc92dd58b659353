// The render driver: splits spp into batches, has the tracer fill them,
// gathers them into the film, reports progress. Tracer-agnostic.
#pragma once

#include "core/film.h"
#include "core/tracer.h"

#include <cstdint>
#include <functional>

namespace pathlab {

struct RenderStats {
  double seconds = 0.0;
  std::uint64_t samples = 0;
  std::uint64_t rays = 0;
  std::uint64_t bad_samples = 0;
  // Radiance clamping (RenderSettings::clamp): samples scaled down, and the
  // sum over all samples of the mean RGB radiance before clamping and of
  // what clamping removed (their ratio is the relative energy removed).
  std::uint64_t clamped_samples = 0;
  double energy_total = 0.0;
  double energy_clamped = 0.0;
};

// Called after each batch with the fraction done (0..1].
using ProgressFn = std::function<void(double fraction)>;

// Renders settings.spp samples per pixel into `film` (which must match the
// scene's resolution and filter).
RenderStats render(const Tracer& tracer, Film& film, const ProgressFn& progress = {});

// Samples per pixel in one batch: about 2^18 samples per batch, at least one
// sample per pixel. Depends only on the resolution and spp.
std::uint32_t batch_size(int width, int height, int spp);

}  // namespace pathlab
