// The wavefront tracer: the reference's estimator refactored the way
// production tracers are. One path per work item; recursion turned into a
// loop that carries the throughput forward; every stage run over arrays of
// paths (structure of arrays): generate camera rays -> intersect -> add
// emission -> sample lights -> trace shadow rays -> add light -> scatter ->
// compact the survivors. Paths are processed in waves of a bounded size,
// whatever the resolution and sample count.
//
// Same sample contract as the reference (rng.h, sample_dims.h) and the same
// strategy weights (strategy_weights.h): the same seed gives the same path,
// vertex for vertex, up to floating-point rounding of the sums.
#pragma once

#include "core/tracer.h"

#include <cstddef>

namespace pathlab {

class WavefrontTracer final : public Tracer {
 public:
  static constexpr std::size_t kDefaultWaveSize = std::size_t{1} << 20;
  // How rays reach Embree: ray streams (rtcIntersect1M / rtcOccluded1M) or
  // one rtcIntersect1 / rtcOccluded1 per ray.
  enum class RayQueries { Streams, OneByOne };

  WavefrontTracer(const CompiledScene& scene, const RenderSettings& settings,
                  std::size_t wave_size = kDefaultWaveSize, RayQueries queries = RayQueries::Streams);

  std::string_view name() const override { return "wavefront"; }
  void render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const override;
  FilmSample trace_sample(std::uint32_t x, std::uint32_t y, std::uint32_t sample,
                          PathObserver* observer) const override;

  // Memory the path state of one wave takes per path, in bytes.
  static std::size_t bytes_per_path();
  std::size_t wave_size() const { return wave_size_; }

 private:
  struct Wave;
  void run_wave(Wave& wave, PathObserver* observer) const;
  void intersect(Wave& w) const;
  void add_emission(Wave& w, PathObserver* obs) const;
  void sample_lights(Wave& w) const;
  void trace_shadow_rays(Wave& w) const;
  void add_light(Wave& w, PathObserver* obs) const;
  void scatter(Wave& w, PathObserver* obs) const;
  static void compact(Wave& w);

  std::size_t wave_size_;
  RayQueries queries_;
};

}  // namespace pathlab
