// The wavefront tracer: the reference's estimator refactored the way
// production tracers are. One path per work item; recursion turned into a
// loop that carries the throughput forward; every stage run over arrays of
// paths: generate camera rays -> intersect -> add emission -> sample lights
// -> trace shadow rays -> add light -> scatter -> compact the survivors.
// Paths are processed in waves of a bounded size, whatever the resolution
// and sample count. Two implementations of the stages: scalar ones over
// arrays of records (Ray, Surfel, ...), which run every scene, and
// vectorised ones over one array per scalar (vector_stages.h), which run the
// scenes they model at the SIMD target core/simd/simd.h selected (AVX-512,
// AVX2 or SSE4).
//
// Same sample contract as the reference (rng.h, sample_dims.h) and the same
// strategy weights (strategy_weights.h): the same seed gives the same path,
// vertex for vertex, up to floating-point rounding of the sums.
#pragma once

#include "core/tracer.h"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace pathlab {

// How each kind of ray reaches Embree (core/embree_accel.h). The defaults
// are the fastest on the dragon benchmark on this project's 2-core AVX-512
// machine (bench/bench_tracers.cpp measures every mode, --modes= any other
// mix; docs/performance.md): streams of every kind, which Embree reads
// straight from the vectorised stages' arrays (camera streams marked
// coherent).
struct WavefrontRayModes {
  RayBatchMode camera = RayBatchMode::Stream;
  RayBatchMode bounce = RayBatchMode::Stream;
  RayBatchMode shadow = RayBatchMode::Stream;
};

// The wavefront's stages, as its clock times them (Embree's batches apart).
enum class WavefrontStage : std::uint8_t {
  Camera,    // camera rays
  Resolve,   // hits into surfels (the prefetch included)
  Emission,  // emission found by rays, its MIS weight, paths that end
  Lights,    // light samples, their BSDF values and shadow rays
  AddLight,  // the light of the visible ones
  Scatter,   // continuations, roulette, next rays
  Compact,   // finished samples out, survivors packed (the last)
};
inline constexpr int kWavefrontStages = static_cast<int>(WavefrontStage::Compact) + 1;
const char* wavefront_stage_name(WavefrontStage stage);

// Where a wavefront's time went, summed over its renders and threads: the
// ray queries of each kind (time inside EmbreeAccel's batch calls) and each
// stage's own time against the whole of tracing its waves. Rays per second
// here are per thread.
struct WavefrontTimes {
  struct Queries {
    std::uint64_t rays = 0;
    double seconds = 0.0;
    double rays_per_second() const { return seconds > 0.0 ? static_cast<double>(rays) / seconds : 0.0; }
  };
  Queries camera, bounce, shadow;
  double waves_seconds = 0.0;  // run_wave, start to end, all waves
  double stage_seconds[kWavefrontStages] = {};  // each stage's own time (WavefrontStage), Embree's apart
  double query_seconds() const { return camera.seconds + bounce.seconds + shadow.seconds; }
};

// Which implementation runs the stages (vector_stages.h).
enum class WavefrontStages : std::uint8_t {
  Auto,    // the vectorised stages when the scene and the processor allow them
  Scalar,  // the scalar stages always (the baseline they are measured and tested against)
};

// One path's state at a chosen vertex K, for `render --dump-stage-buffers`
// (docs/aov.md): what the per-path arrays held while the ray reaching
// vertex K (the camera ray for K = 1) was processed.
struct StageRecord {
  Spectrum throughput{0.0f};  // the path throughput that ray carries
  vec3 dir{0.0f};             // its direction
  float distance = 0.0f;      // to the surface it hit (infinity: it escaped)
  float light_pdf = 0.0f;     // the area light sample's pdf at vertex K (0: none taken)
  bool reached = false;       // the path was still alive to trace that ray
  bool light_sampled = false; // an area light sample was taken at vertex K
  bool survived = false;      // alive after that bounce's compaction (goes on to vertex K + 1)
};

class WavefrontTracer final : public Tracer {
 public:
  // Paths per wave, at most: a batch is cut into waves of this size, or
  // smaller ones (down to 256 paths) when the batch has fewer than 64 such
  // waves, so that every thread has work. One thread runs a wave through all
  // its stages; 4,096 paths of state fit in the caches (docs/performance.md).
  static constexpr std::size_t kDefaultWaveSize = std::size_t{1} << 12;
  using RayModes = WavefrontRayModes;

  WavefrontTracer(const CompiledScene& scene, const RenderSettings& settings,
                  std::size_t wave_size = kDefaultWaveSize, RayModes modes = {},
                  WavefrontStages stages = WavefrontStages::Auto);
  ~WavefrontTracer() override;

  std::string_view name() const override { return "wavefront"; }
  void render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const override;
  FilmSample trace_sample(std::uint32_t x, std::uint32_t y, std::uint32_t sample,
                          PathObserver* observer) const override;

  // render_batch through the scalar stages that also records, for every
  // sample of the batch, its path's state at vertex `vertex` into
  // records[its slot] (pixel-major like `out`; a path that ended before
  // has reached = false). Costs the normal render one untaken branch per
  // wave and bounce.
  void render_batch_recording(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out, int vertex,
                              std::span<StageRecord> records) const;

  // Memory the path state of one wave takes per path, in bytes.
  std::size_t bytes_per_path() const;
  std::size_t wave_size() const { return wave_size_; }
  const RayModes& ray_modes() const { return modes_; }
  // Whether the stages run vectorised (vector_stages.h: 16, 8 or 4 paths
  // per register, paths as one array per scalar): the scene needs only
  // Lambert surfaces and triangle area lights, the strategy is not
  // "cosine", and the SIMD target is not scalar. Tracing one sample with an
  // observer always runs the scalar stages (they report every event); the
  // paths are the same bits either way.
  bool vectorised() const;
  // Why the stages run scalar ("" when vectorised), e.g. "strategy cosine".
  const std::string& scalar_reason() const { return scalar_reason_; }
  // Which stages run vectorised, in a line for people.
  std::string stages_description() const;
  // Time spent so far (a clock read per batch of rays, not per ray).
  WavefrontTimes times() const;

 private:
  struct Clock;
  struct Wave;
  struct Lanes;
  // Traces the wave's paths to their ends, writing each one's sample to
  // out[its out_index] as it ends.
  void run_wave(Wave& wave, std::span<FilmSample> out, PathObserver* observer) const;
  // render_batch, and render_batch_recording when `records` is not empty.
  void render_waves(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out, int record_vertex,
                    std::span<StageRecord> records) const;
  // The wave's paths at the recorded vertex: before scattering, then after.
  static void record_stage(Wave& w);
  static void record_survival(Wave& w);
  void generate_camera_rays(Wave& w, PathObserver* obs) const;
  void intersect(Wave& w) const;
  void add_emission(Wave& w, PathObserver* obs) const;
  void sample_lights(Wave& w, PathObserver* obs) const;
  void trace_shadow_rays(Wave& w) const;
  void add_light(Wave& w, PathObserver* obs) const;
  void scatter(Wave& w, PathObserver* obs) const;
  static void compact(Wave& w, std::span<FilmSample> out);
  // The same over Lanes; `out` is the wave's own samples, the ones whose
  // output slots are first_slot, first_slot + 1, ...
  void run_wave_vector(Lanes& lanes, std::span<FilmSample> out, std::uint32_t first_slot) const;
  // Adds one wave's clock to what times() reports.
  void publish(const Clock& clock) const;
  static std::size_t scalar_bytes_per_path();

  struct VectorStages;
  std::size_t wave_size_;
  RayModes modes_;
  std::string scalar_reason_;
  std::unique_ptr<const VectorStages> vector_;  // null: scalar stages
  // What times() reports: nanoseconds of each, and rays of each kind of query.
  // The clock's entries: the three kinds of queries, the whole wave, then
  // each WavefrontStage.
  enum Clocked { kCameraQueries, kBounceQueries, kShadowQueries, kWave, kFirstStage, kClocked = kFirstStage + kWavefrontStages };
  mutable std::atomic<std::uint64_t> nanoseconds_[kClocked] = {}, rays_[kWave] = {};
};

}  // namespace pathlab
