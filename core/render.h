// The render driver: splits spp into batches, has the tracer fill them,
// gathers them into the film, reports progress. Tracer-agnostic.
#pragma once

#include "core/film.h"
#include "core/fixed_sum.h"
#include "core/tracer.h"

#include <cstdint>
#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace pathlab {

struct RenderStats {
  double seconds = 0.0;
  std::uint64_t samples = 0;
  std::uint64_t rays = 0;
  std::uint64_t bad_samples = 0;
  // Radiance clamping (RenderSettings::clamp): samples scaled down, and the
  // sum over all samples of the mean RGB radiance before clamping and of
  // what clamping removed (their ratio is the relative energy removed).
  // Fixed-point, so that a render in pieces sums to the same bits.
  std::uint64_t clamped_samples = 0;
  Sum1 energy_total;
  Sum1 energy_clamped;
  double relative_energy_clamped() const {
    return energy_total.value() > 0.0 ? energy_clamped.value() / energy_total.value() : 0.0;
  }

  // Adds the counts of another render of the same film (seconds and
  // bad_samples, which describe the whole film, are left to the caller).
  RenderStats& operator+=(const RenderStats& o) {
    samples += o.samples;
    rays += o.rays;
    clamped_samples += o.clamped_samples;
    energy_total += o.energy_total;
    energy_clamped += o.energy_clamped;
    return *this;
  }
};

// Called after each batch with the fraction done (0..1].
using ProgressFn = std::function<void(double fraction)>;
// Called after each batch, once the film holds samples [.., end) of every
// pixel, with the stats of the render so far; returning false stops the
// render there (at whole passes: a checkpoint, an interrupt).
using BatchDoneFn = std::function<bool(std::uint32_t end, const RenderStats& so_far)>;

// Renders settings.spp samples per pixel into `film` (which must match the
// scene's resolution and filter): render_samples(tracer, film, 0, spp).
RenderStats render(const Tracer& tracer, Film& film, const ProgressFn& progress = {});

// Progressive rendering. The film accumulates and samples are keyed by
// (seed, pixel, sample index), so rendering samples [first, last) into a film
// that holds samples [0, first) gives exactly the film of a render with
// `last` samples per pixel. With settings.clamp > 0 each sample's radiance is
// scaled so that its largest component is at most clamp (counted in
// clamped_samples, energy_clamped).
// `batch_done` may stop it early: RenderStats::samples then says how far it
// got (samples / pixels passes).
RenderStats render_samples(const Tracer& tracer, Film& film, std::uint32_t first, std::uint32_t last,
                           const ProgressFn& progress = {}, const BatchDoneFn& batch_done = {});

// When render_until() stops. Zero fields are off; max_spp always applies.
struct StopRule {
  double time_budget_seconds = 0.0;  // wall clock: no pass that would end past it is started
  double target_relmse = 0.0;        // stop once estimated_relmse(film) < target
  int max_spp = 1 << 24;
  // Samples per pixel per pass; 0: batch_size(width, height, max_spp).
  std::uint32_t pass_spp = 0;
};
struct UntilResult {
  RenderStats stats;
  std::uint32_t spp = 0;          // samples per pixel reached (whole passes)
  std::uint32_t passes = 0;
  double estimated_relmse = 0.0;  // of the final film
  double last_pass_seconds = 0.0;
};
// Renders whole passes into an empty `film` until the rule says stop. Before
// each pass after the first it predicts the pass's time as the mean of the
// passes so far and does not start it if it would end past the time budget,
// so the render ends at most about one pass before the budget. It estimates
// the film's error from its variance, so `film` must keep it
// (FilmMoments::MeanAndVariance; a mean-only film throws std::logic_error).
// `start_spp`: the film already holds samples [0, start_spp) (a resumed
// render), and the passes go on from there on the same grid as from 0.
// `batch_done` as for render_samples.
UntilResult render_until(const Tracer& tracer, Film& film, const StopRule& rule, const ProgressFn& progress = {},
                         std::uint32_t start_spp = 0, const BatchDoneFn& batch_done = {});

// The relative error of the film's image estimated from its own per-pixel
// variance: the mean over pixels and channels of Var(I) / (I + 0.01)^2,
// with I the pixel mean (the same denominator as rel_mse in
// debugtools/image_metrics.h, with the estimate standing in for the truth).
double estimated_relmse(const Film& film);

// Room for a batch of samples that nobody has written: every tracer writes
// each sample of the batch it is given (Tracer::render_batch), so the buffer
// is not zeroed first. Its pages then fault in on the threads that trace
// rather than serially in the driver (at 720p, 26 MB took 4-13 ms to zero,
// all of it on one thread while the others waited).
class SampleBuffer {
 public:
  explicit SampleBuffer(std::size_t size);
  // The first `n` samples (n at most the size it was made with).
  std::span<FilmSample> first(std::size_t n) { return std::span<FilmSample>(data_.get(), size_).first(n); }

 private:
  struct Free {
    void operator()(FilmSample* p) const noexcept;
  };
  std::unique_ptr<FilmSample, Free> data_;
  std::size_t size_;
};

// The firefly clamp (RenderSettings::clamp) on one sample, as the film
// receives it: a finite sample whose largest component exceeds `limit` is
// scaled by limit / that component, keeping its colour. limit <= 0 is off;
// a sample outside the film's range (NaN, Inf, huge: in_film_range) is left
// as it is, for the film to count and locate. render_samples() and
// trace-pixel both call this, so a replayed sample reports the film's bits.
Spectrum clamp_radiance(const Spectrum& L, float limit);

// Every setting that changes a sample's bits, as (key, value) text, in a
// fixed order: strategy, seed, sampler, max_depth, rr_depth, bsdf_sampling,
// light_sampling, light_sampler, clamp, min_pdf, general_shading, texture_filter, intersection (and bvh,
// which changes no bit but names the build). Floats are written with 9
// significant digits (they read back to the same float). Recorded in a
// render's EXR header
// ("pathlab:<key>") and in trace-pixel's header and JSON. Not in it: spp
// and the tracer, which the caller records (the zsobol sampler's numbers
// depend on spp too, rounded up to a power of two: core/rng.h; under it a
// last key, zsobol_spp, gives that power of two).
std::vector<std::pair<std::string, std::string>> sample_settings(const RenderSettings& settings);

// The git commit pathlab was built from (12 hex digits, "unknown" outside a
// git checkout), as in the render fingerprint (core/partial_film.h).
const char* git_revision();

// Samples per pixel in one batch: about 2^18 samples per batch, at least one
// sample per pixel. Depends only on the resolution and spp.
std::uint32_t batch_size(int width, int height, int spp);

}  // namespace pathlab
