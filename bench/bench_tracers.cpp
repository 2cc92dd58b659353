// How fast the tracers are, against what Embree alone can do on the same
// rays, measured in one run:
//   Raw/<kind>/<mode>     Embree casting the scene's own camera, bounce and
//                         shadow rays (captured from the reference tracer's
//                         paths), in each batch mode of core/embree_accel.h
//   Tracer/reference      the recursive tracer rendering the frame
//   Tracer/wavefront/...  the wavefront tracer, for several wave sizes and
//                         ray modes
//   After/<kind>/<work>   Embree on one thread casting the captured rays in
//                         chunks of 4,096, each right after a burst of other
//                         work (none, 512-bit, 256-bit or scalar arithmetic):
//                         what the wavefront's vectorised stages cost Embree
//                         through the core's clock (the AVX-512 licence)
// At the end it prints the ratios the wavefront issue asks for (medians over
// --benchmark_repetitions): wavefront / reference samples per second, and
// each tracer's rays per second as a fraction of Embree's raw rate for the
// same mix of rays. Each wavefront repetition is paired with a reference
// render and a raw cast of the captured rays in its own modes, taken beside
// it, so that both ratios compare measurements seconds apart (x_reference,
// x_raw).
//
//   build/bench/pathlab_bench_tracers [--scene=bench/scenes/dragon.json] [--spp=4]
//                                      [--resolution=WxH] [--raw-min-time=SECONDS] [--cpu-time]
//                                      [--waves=1024,4096,65536]
//                                      [--modes=CAMERA/BOUNCE/SHADOW,...]
//                                      [--benchmark_repetitions=5] [--benchmark_filter=...]
#include "bench/processor.h"
#include "bench/ray_capture.h"
#include "core/compiled_scene.h"
#include "core/parallel.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "core/simd/simd.h"
#include "reference/reference_tracer.h"
#include "wavefront/wavefront_tracer.h"

#include <benchmark/benchmark.h>
#include <immintrin.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace pathlab::bench {
namespace {

struct Setup {
  std::string scene_file = PATHLAB_SOURCE_DIR "/bench/scenes/dragon.json";
  // Samples per pixel of each render: enough that allocating the film and
  // the sample buffers (which both tracers pay) is a small part of the time.
  int spp = 4;
  // Rates per second of process CPU time (all threads) instead of wall
  // time: steadier on a machine other work is loading, but blind to threads
  // left idle.
  bool cpu_time = false;
  double raw_min_seconds = 0.5;  // per Raw/ benchmark
  int width = 0, height = 0;     // 0: the scene's own resolution
  // The wave sizes measured in the default ray modes (the other
  // configurations use the default wave size).
  std::vector<std::size_t> waves{std::size_t{1} << 10, WavefrontTracer::kDefaultWaveSize, std::size_t{1} << 16};
  // More ray modes (camera/bounce/shadow) measured at the default wave size,
  // beside the defaults and the all-one-mode configurations: to choose the
  // defaults on another machine.
  std::vector<WavefrontRayModes> modes;
  std::unique_ptr<CompiledScene> scene;
  RenderSettings settings;
  CapturedRays rays;
};
Setup& setup() {
  static Setup s;
  return s;
}

// --- raw Embree ---------------------------------------------------------------

void raw(benchmark::State& state, RayKind kind, RayBatchMode mode) {
  const Setup& s = setup();
  const RayList& rays = s.rays.of(kind);
  std::size_t hits = 0;
  for (auto _ : state) hits = cast(*s.scene, rays, kind, mode);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * rays.size()));
  state.counters["rays/s"] = benchmark::Counter(static_cast<double>(state.iterations() * rays.size()),
                                                benchmark::Counter::kIsRate);
  state.counters["hit_fraction"] = rays.empty() ? 0.0 : static_cast<double>(hits) / static_cast<double>(rays.size());
}

// The mode a wavefront run casts rays of `kind` in.
RayBatchMode mode_of(const WavefrontRayModes& modes, RayKind kind) {
  return kind == RayKind::Camera ? modes.camera : kind == RayKind::Bounce ? modes.bounce : modes.shadow;
}

// --- Embree after other work ----------------------------------------------------
// Dense 512-bit floating-point work lowers the clock of a Skylake-SP or
// Cascade Lake core (its "AVX-512 licence") for about two milliseconds after
// the work ends, and 256-bit work does so less. Between two Embree batches
// of a wave the vectorised stages do such work, so Embree then runs slower
// than in Raw/, which casts batch after batch. After/ measures that on one
// core: each chunk of rays right after a burst of about as many operations
// as the stages spend on it, Embree's time alone on the clock.

enum class Burst { None, Zmm, Ymm, Scalar };
const char* burst_name(Burst b) {
  switch (b) {
    case Burst::None: return "none";
    case Burst::Zmm: return "zmm";
    case Burst::Ymm: return "ymm";
    case Burst::Scalar: return "scalar";
  }
  return "?";
}
constexpr int kBurstSteps = 20000;  // three dependent chains of multiplies and adds: ~60 us

__attribute__((target("avx512f"), noinline)) float burst_zmm(float x) {
  __m512 a = _mm512_set1_ps(x), b = _mm512_set1_ps(1.0001f), c = _mm512_set1_ps(0.9999f), d = a, e = b;
  for (int i = 0; i < kBurstSteps; ++i) a = _mm512_mul_ps(a, b), d = _mm512_mul_ps(d, c), e = _mm512_add_ps(e, a);
  alignas(64) float out[16];  // (not _mm512_reduce_add_ps: GCC 12 warns inside it, PR 105593)
  _mm512_store_ps(out, _mm512_add_ps(_mm512_add_ps(a, d), e));
  return out[0] + out[15];
}
__attribute__((target("avx2"), noinline)) float burst_ymm(float x) {
  __m256 a = _mm256_set1_ps(x), b = _mm256_set1_ps(1.0001f), c = _mm256_set1_ps(0.9999f), d = a, e = b;
  for (int i = 0; i < kBurstSteps; ++i) a = _mm256_mul_ps(a, b), d = _mm256_mul_ps(d, c), e = _mm256_add_ps(e, a);
  alignas(32) float out[8];
  _mm256_store_ps(out, _mm256_add_ps(_mm256_add_ps(a, d), e));
  return out[0] + out[7];
}
__attribute__((noinline)) float burst_scalar(float x) {
  float a = x, d = x, e = 1.0f;
  for (int i = 0; i < kBurstSteps; ++i) {
    a *= 1.0001f, d *= 0.9999f, e += a;
    benchmark::DoNotOptimize(e);
  }
  return a + d + e;
}

void after_burst(benchmark::State& state, RayKind kind, Burst burst) {
  if ((burst == Burst::Zmm && !__builtin_cpu_supports("avx512f")) ||
      (burst == Burst::Ymm && !__builtin_cpu_supports("avx2"))) {
    state.SkipWithError("the processor lacks the instructions of this burst");
    return;
  }
  const Setup& s = setup();
  const RayList& rays = s.rays.of(kind);
  const RayBatchMode mode = mode_of(WavefrontRayModes{}, kind);  // as the wavefront casts them
  HitBuffers hits(kCastChunk);
  float sink = 1.0f;
  for (auto _ : state) {
    double embree_seconds = 0.0;
    for (std::size_t b = 0; b < rays.size(); b += kCastChunk) {
      if (burst == Burst::Zmm) sink += burst_zmm(sink);
      if (burst == Burst::Ymm) sink += burst_ymm(sink);
      if (burst == Burst::Scalar) sink += burst_scalar(sink);
      const auto t0 = std::chrono::steady_clock::now();
      cast_batch(*s.scene, rays, b, std::min(kCastChunk, rays.size() - b), kind, mode, hits);
      embree_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    state.SetIterationTime(embree_seconds);
  }
  benchmark::DoNotOptimize(sink);
  state.counters["rays/s"] = benchmark::Counter(static_cast<double>(state.iterations() * rays.size()),
                                                benchmark::Counter::kIsIterationInvariantRate);
}

std::string after_name(RayKind kind, Burst burst) {
  return std::string("After/") + ray_kind_name(kind) + "/" + burst_name(burst);
}

static_assert(kCastChunk == WavefrontTracer::kDefaultWaveSize, "raw casts hand Embree a default wave's rays at a time");

// --- tracers --------------------------------------------------------------------

// Seconds on the clock the run is measured by: wall time, or the process's
// CPU time (all threads) with --cpu-time.
double now_seconds() {
  if (setup().cpu_time) return static_cast<double>(std::clock()) / CLOCKS_PER_SEC;
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

RenderStats render_frame(const Tracer& tracer) {
  const FilmDesc& fd = setup().scene->scene().film;
  // The film of a plain `pathlab render`, which writes the image alone.
  Film film(fd.width, fd.height, fd.filter, FilmMoments::Mean);
  const RenderStats stats = render(tracer, film);
  benchmark::DoNotOptimize(film.image().pixels.data());
  return stats;
}

void set_rates(benchmark::State& state, const RenderStats& stats) {
  state.counters["samples/s"] = benchmark::Counter(static_cast<double>(state.iterations() * stats.samples),
                                                   benchmark::Counter::kIsRate);
  state.counters["rays/s"] =
      benchmark::Counter(static_cast<double>(state.iterations() * stats.rays), benchmark::Counter::kIsRate);
  state.counters["rays/sample"] = static_cast<double>(stats.rays) / static_cast<double>(stats.samples);
}

void reference(benchmark::State& state) {
  const ReferenceTracer tracer(*setup().scene, setup().settings);
  RenderStats stats;
  for (auto _ : state) stats = render_frame(tracer);
  set_rates(state, stats);
}

// The wavefront, paired with its baselines: each iteration also renders the
// frame with the reference and casts the captured rays with Embree alone in
// the run's modes, just before or just after (alternating), outside the
// timed region. Its counters x_reference = reference time / wavefront time
// and x_raw = wavefront rays/s / raw rays/s compare measurements taken
// seconds apart, so a machine whose speed drifts by 10 % between
// repetitions (as this shared one does) moves both sides alike.
void wavefront(benchmark::State& state, std::size_t wave, WavefrontRayModes modes, WavefrontStages stages) {
  const ReferenceTracer reference_tracer(*setup().scene, setup().settings);
  const WavefrontTracer tracer(*setup().scene, setup().settings, wave, modes, stages);
  static std::uint64_t pairs = 0;
  RenderStats stats;
  double reference_seconds = 0.0, wavefront_seconds = 0.0;
  const CapturedRays& captured = setup().rays;
  double raw_seconds = 0.0, raw_rays = 0.0;
  auto time_baselines = [&] {
    state.PauseTiming();
    const double t0 = now_seconds();
    render_frame(reference_tracer);
    reference_seconds += now_seconds() - t0;
    for (RayKind kind : kAllRayKinds) {
      const RayBatchMode mode = mode_of(modes, kind);
      const double t1 = now_seconds();
      cast(*setup().scene, captured.of(kind), kind, mode);
      raw_seconds += now_seconds() - t1;
      raw_rays += static_cast<double>(captured.of(kind).size());
    }
    state.ResumeTiming();
  };
  for (auto _ : state) {
    const bool reference_first = (pairs++ % 2) == 0;
    if (reference_first) time_baselines();
    const double t0 = now_seconds();
    stats = render_frame(tracer);
    wavefront_seconds += now_seconds() - t0;
    if (!reference_first) time_baselines();
  }
  set_rates(state, stats);
  state.counters["x_reference"] = wavefront_seconds > 0.0 ? reference_seconds / wavefront_seconds : 0.0;
  const double tracer_rate = static_cast<double>(state.iterations() * stats.rays) / wavefront_seconds;
  state.counters["x_raw"] = raw_seconds > 0.0 && wavefront_seconds > 0.0 ? tracer_rate / (raw_rays / raw_seconds) : 0.0;
  state.counters["vectorised"] = tracer.vectorised() ? 1.0 : 0.0;
  // Embree as the wavefront meets it, between its stages: the share of the
  // waves' time it takes, and its rates on all threads, to set beside Raw/.
  const WavefrontTimes t = tracer.times();
  // Raw/ rates are per second of the clock the run uses: wall time (all
  // threads casting) or, with --cpu-time, CPU time summed over threads,
  // which is a single thread's rate.
  const double threads = setup().cpu_time ? 1.0 : static_cast<double>(max_threads());
  state.counters["embree_share"] = t.waves_seconds > 0.0 ? t.query_seconds() / t.waves_seconds : 0.0;
  // The share of the render's time (on all threads) spent inside the waves;
  // the rest is the film, the sample buffer and the threads' idle tails.
  // Under --cpu-time this is approximate: the waves are timed on the steady
  // clock, the render in process CPU time (which also counts TBB spinning).
  state.counters["waves_share"] = wavefront_seconds > 0.0 ? t.waves_seconds / (threads * wavefront_seconds) : 0.0;
  state.counters["camera_in_context"] = threads * t.camera.rays_per_second();
  state.counters["bounce_in_context"] = threads * t.bounce.rays_per_second();
  state.counters["shadow_in_context"] = threads * t.shadow.rays_per_second();
  // Each stage's share of the waves' time (WavefrontStage; Embree's batches apart).
  for (int k = 0; k < kWavefrontStages; ++k)
    state.counters[std::string("stage_") + wavefront_stage_name(static_cast<WavefrontStage>(k))] =
        t.waves_seconds > 0.0 ? t.stage_seconds[k] / t.waves_seconds : 0.0;
}

// --- the summary ------------------------------------------------------------------

// Keeps every run's counters and prints the ratios when the benchmarks end.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    // Keyed by the name it was registered under, without Google Benchmark's
    // "/iterations:1/real_time" suffixes. Single runs are kept (their median
    // is taken below); so are "median" aggregates, which stand for runs that
    // --benchmark_report_aggregates_only left out.
    for (const Run& r : runs) {
      const bool aggregate = r.run_type == Run::RT_Aggregate;
      if (aggregate && r.aggregate_name != "median" && r.aggregate_name != "stddev") continue;
      auto& counters = (!aggregate ? values_ : r.aggregate_name == "median" ? medians_ : stddevs_)[r.run_name.function_name];
      for (const auto& [name, counter] : r.counters) counters[name].push_back(counter.value);
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    print_summary();
  }

 private:
  double median(const std::string& run, const std::string& counter) const {
    const bool aggregated = medians_.count(run) != 0;
    const auto& source = aggregated ? medians_ : values_;
    const auto r = source.find(run);
    if (r == source.end()) return 0.0;
    const auto c = r->second.find(counter);
    if (c == r->second.end() || c->second.empty()) return 0.0;
    std::vector<double> v = c->second;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  }
  // Embree's raw rate for the tracer's mix of rays, each kind cast in `modes`:
  // rays per second of the whole mix (harmonic, weighted by the mix).
  double raw_mix_rate(const WavefrontRayModes& modes) const {
    const CapturedRays& c = setup().rays;
    const double total = static_cast<double>(c.total());
    double seconds_per_ray = 0.0;
    for (RayKind kind : kAllRayKinds) {
      const RayBatchMode mode = mode_of(modes, kind);
      const double rate = median(raw_name(kind, mode), "rays/s");
      if (rate <= 0.0) return 0.0;
      seconds_per_ray += static_cast<double>(c.of(kind).size()) / total / rate;
    }
    return 1.0 / seconds_per_ray;
  }
  void print_summary() const {
    std::printf("\n== summary (medians) ==\n");
    const CapturedRays& c = setup().rays;
    std::printf("ray mix (captured from the reference's paths, %zu samples): camera %.1f%%, bounce %.1f%%, shadow %.1f%%\n",
                c.samples, 100.0 * static_cast<double>(c.camera.size()) / static_cast<double>(c.total()),
                100.0 * static_cast<double>(c.bounce.size()) / static_cast<double>(c.total()),
                100.0 * static_cast<double>(c.shadow.size()) / static_cast<double>(c.total()));
    for (RayKind kind : kAllRayKinds) {
      std::printf("raw %-7s", ray_kind_name(kind));
      for (RayBatchMode mode : kAllRayBatchModes)
        std::printf("  %s %.3g rays/s", ray_batch_mode_name(mode), median(raw_name(kind, mode), "rays/s"));
      std::printf("\n");
    }
    const double ref_sps = median("Tracer/reference", "samples/s");
    const double ref_rps = median("Tracer/reference", "rays/s");
    const WavefrontRayModes single{RayBatchMode::Single, RayBatchMode::Single, RayBatchMode::Single};
    const double raw_single = raw_mix_rate(single);
    std::printf("reference: %.4g samples/s, %.4g rays/s = %.2f of raw (all single rays, %.4g rays/s)\n", ref_sps,
                ref_rps, raw_single > 0 ? ref_rps / raw_single : 0.0, raw_single);
    // The speed of light: Embree alone, each kind of ray in its fastest mode.
    // A tracer whose every other cost were zero would reach this rate; what
    // the reference spends beyond its own (single-ray) Embree time is its
    // "rest", and a target of 1.3x leaves the wavefront this share of it.
    auto fastest = [&](RayKind kind) {
      RayBatchMode best = RayBatchMode::Single;
      for (RayBatchMode mode : kAllRayBatchModes)
        if (median(raw_name(kind, mode), "rays/s") > median(raw_name(kind, best), "rays/s")) best = mode;
      return best;
    };
    const WavefrontRayModes best{fastest(RayKind::Camera), fastest(RayKind::Bounce), fastest(RayKind::Shadow)};
    const double raw_best = raw_mix_rate(best);
    const double rays_per_sample = median("Tracer/reference", "rays/sample");
    if (ref_sps > 0 && raw_best > 0 && raw_single > 0 && rays_per_sample > 0) {
      const double t_ref = 1.0 / ref_sps, embree_ref = rays_per_sample / raw_single;
      const double embree_best = rays_per_sample / raw_best, rest_ref = t_ref - embree_ref;
      std::printf("speed of light: Embree alone in the fastest modes (camera %s, bounce %s, shadow %s) = %.2fx the "
                  "reference;\n  the reference spends %.0f%% of its time outside Embree; at 1.3x the wavefront may "
                  "spend %.2f of that, at 75%% of raw %.2f\n",
                  ray_batch_mode_name(best.camera), ray_batch_mode_name(best.bounce), ray_batch_mode_name(best.shadow),
                  t_ref / embree_best, 100.0 * rest_ref / t_ref,
                  rest_ref > 0 ? (t_ref / 1.3 - embree_best) / rest_ref : 0.0,
                  rest_ref > 0 ? (embree_best / 0.75 - embree_best) / rest_ref : 0.0);
    }
    // Embree after the bursts, against after none (one core).
    for (RayKind kind : kAllRayKinds) {
      const double none = median(after_name(kind, Burst::None), "rays/s");
      if (none <= 0.0) continue;
      std::printf("Embree on one core, %s rays, right after a burst of work, of its rate after none:", ray_kind_name(kind));
      for (Burst b : {Burst::Zmm, Burst::Ymm, Burst::Scalar})
        std::printf(" %s %.2f", burst_name(b), median(after_name(kind, b), "rays/s") / none);
      std::printf("\n");
    }
    std::vector<std::string> runs;
    for (const auto* source : {&values_, &medians_})
      for (const auto& entry : *source)
        if (entry.first.rfind("Tracer/wavefront", 0) == 0 &&
            std::find(runs.begin(), runs.end(), entry.first) == runs.end())
          runs.push_back(entry.first);
    for (const std::string& run : runs) {
      const WavefrontRayModes modes = parse_modes(run);
      const double sps = median(run, "samples/s"), rps = median(run, "rays/s");
      const double raw_rate = raw_mix_rate(modes);
      std::printf("%s: %.4g samples/s = %.2fx reference (paired, sd %.2f); %.4g rays/s = %.2f of raw (paired, sd "
                  "%.2f; %.2f of the Raw/ medians' %.4g rays/s); %s stages\n",
                  run.c_str(), sps, median(run, "x_reference"), stddev(run, "x_reference"), rps, median(run, "x_raw"),
                  stddev(run, "x_raw"), raw_rate > 0 ? rps / raw_rate : 0.0, raw_rate,
                  median(run, "vectorised") > 0.5 ? "vectorised" : "scalar");
      // Embree's rate inside the tracer against its raw rate in the same mode.
      auto in_context = [&](const char* counter, RayKind kind, RayBatchMode mode) {
        const double raw_kind = median(raw_name(kind, mode), "rays/s");
        return raw_kind > 0 ? median(run, counter) / raw_kind : 0.0;
      };
      std::printf("  waves %.0f%% of the render's time; Embree %.0f%% of the waves' time; in context at %.2f "
                  "(camera), %.2f (bounce), %.2f (shadow) of its raw rates\n",
                  100.0 * median(run, "waves_share"), 100.0 * median(run, "embree_share"),
                  in_context("camera_in_context", RayKind::Camera, modes.camera),
                  in_context("bounce_in_context", RayKind::Bounce, modes.bounce),
                  in_context("shadow_in_context", RayKind::Shadow, modes.shadow));
      std::printf("  stages (of the waves' time):");
      for (int k = 0; k < kWavefrontStages; ++k) {
        const char* name = wavefront_stage_name(static_cast<WavefrontStage>(k));
        std::printf("%s %s %.1f%%", k ? "," : "", name, 100.0 * median(run, std::string("stage_") + name));
      }
      std::printf("\n");
    }
  }
  static WavefrontRayModes parse_modes(const std::string& run) {
    WavefrontRayModes m;
    for (RayBatchMode mode : kAllRayBatchModes) {
      const std::string n = ray_batch_mode_name(mode);
      if (run.find("camera:" + n) != std::string::npos) m.camera = mode;
      if (run.find("bounce:" + n) != std::string::npos) m.bounce = mode;
      if (run.find("shadow:" + n) != std::string::npos) m.shadow = mode;
    }
    return m;
  }
  // The sample standard deviation of a counter over the repetitions (0 for
  // fewer than two).
  double stddev(const std::string& run, const std::string& counter) const {
    if (const auto r = stddevs_.find(run); r != stddevs_.end()) {
      const auto c = r->second.find(counter);
      return c == r->second.end() || c->second.empty() ? 0.0 : c->second.front();
    }
    const auto r = values_.find(run);
    if (r == values_.end()) return 0.0;
    const auto c = r->second.find(counter);
    if (c == r->second.end() || c->second.size() < 2) return 0.0;
    const std::vector<double>& v = c->second;
    double mean = 0.0, ss = 0.0;
    for (double x : v) mean += x / static_cast<double>(v.size());
    for (double x : v) ss += (x - mean) * (x - mean);
    return std::sqrt(ss / static_cast<double>(v.size() - 1));
  }
  using Counters = std::map<std::string, std::map<std::string, std::vector<double>>>;
  Counters values_, medians_, stddevs_;
};

std::string wavefront_name(std::size_t wave, const WavefrontRayModes& m, WavefrontStages stages) {
  return "Tracer/wavefront/wave:" + std::to_string(wave) + "/camera:" + ray_batch_mode_name(m.camera) +
         "/bounce:" + ray_batch_mode_name(m.bounce) + "/shadow:" + ray_batch_mode_name(m.shadow) +
         (stages == WavefrontStages::Scalar ? "/stages:scalar" : "");
}

benchmark::internal::Benchmark* timed(benchmark::internal::Benchmark* b) {
  b->Unit(benchmark::kMillisecond);
  return setup().cpu_time ? b->MeasureProcessCPUTime() : b->UseRealTime();
}

void register_benchmarks() {
  for (RayKind kind : kAllRayKinds)
    for (RayBatchMode mode : kAllRayBatchModes)
      timed(benchmark::RegisterBenchmark(raw_name(kind, mode).c_str(), raw, kind, mode))->MinTime(setup().raw_min_seconds);
  for (RayKind kind : kAllRayKinds)
    for (Burst b : {Burst::None, Burst::Zmm, Burst::Ymm, Burst::Scalar})
      benchmark::RegisterBenchmark(after_name(kind, b).c_str(), after_burst, kind, b)
          ->Unit(benchmark::kMillisecond)
          ->UseManualTime()
          ->Iterations(2);
  timed(benchmark::RegisterBenchmark("Tracer/reference", reference))->Iterations(1);
  struct Config {
    std::size_t wave;
    WavefrontRayModes modes;
    WavefrontStages stages = WavefrontStages::Auto;
  };
  std::vector<Config> configs;
  const WavefrontRayModes defaults;
  const std::size_t wave = WavefrontTracer::kDefaultWaveSize;
  for (std::size_t w : setup().waves) configs.push_back({w, defaults});
  for (RayBatchMode mode : kAllRayBatchModes) configs.push_back({wave, {mode, mode, mode}});
  for (const WavefrontRayModes& m : setup().modes) configs.push_back({wave, m});
  // The scalar stages, the baseline of the vectorised ones.
  configs.push_back({wave, defaults, WavefrontStages::Scalar});
  configs.push_back({wave, {RayBatchMode::Single, RayBatchMode::Single, RayBatchMode::Single}, WavefrontStages::Scalar});
  std::vector<std::string> names;
  for (const Config& c : configs) {
    const std::string name = wavefront_name(c.wave, c.modes, c.stages);
    if (std::find(names.begin(), names.end(), name) != names.end()) continue;  // --modes repeated one
    names.push_back(name);
    timed(benchmark::RegisterBenchmark(name.c_str(), wavefront, c.wave, c.modes, c.stages))->Iterations(1);
  }
}

// `text` cut at every `sep` ("a,,b" gives "a", "", "b").
std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  for (std::size_t begin = 0;;) {
    const std::size_t end = text.find(sep, begin);
    parts.push_back(text.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
    if (end == std::string::npos) return parts;
    begin = end + 1;
  }
}

// "packet16/stream/stream": the camera, bounce and shadow modes; nullopt if
// that is not what `text` says.
std::optional<WavefrontRayModes> parse_mode_triple(const std::string& text) {
  const std::vector<std::string> names = split(text, '/');
  if (names.size() != 3) return std::nullopt;
  RayBatchMode parsed[3];
  for (int k = 0; k < 3; ++k) {
    const auto* mode = std::find_if(std::begin(kAllRayBatchModes), std::end(kAllRayBatchModes),
                                    [&](RayBatchMode m) { return names[k] == ray_batch_mode_name(m); });
    if (mode == std::end(kAllRayBatchModes)) return std::nullopt;
    parsed[k] = *mode;
  }
  return WavefrontRayModes{parsed[0], parsed[1], parsed[2]};
}

}  // namespace
}  // namespace pathlab::bench

int main(int argc, char** argv) {
  using namespace pathlab;
  using namespace pathlab::bench;
  Setup& s = setup();
  // Our own flags first; the rest go to Google Benchmark.
  std::vector<char*> rest{argv[0]};
  std::optional<SimdTarget> simd;  // --simd=NAME, else $PATHLAB_SIMD, else the best the processor runs
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--scene=", 8) == 0)
      s.scene_file = argv[i] + 8;
    else if (std::strncmp(argv[i], "--raw-min-time=", 15) == 0)
      s.raw_min_seconds = std::max(0.001, std::atof(argv[i] + 15));
    else if (std::strncmp(argv[i], "--resolution=", 13) == 0)
      std::sscanf(argv[i] + 13, "%dx%d", &s.width, &s.height);
    else if (std::strcmp(argv[i], "--cpu-time") == 0)
      s.cpu_time = true;
    else if (std::strncmp(argv[i], "--simd=", 7) == 0) {
      const std::optional<SimdTarget> t = parse_simd_target(argv[i] + 7);
      if (!t) {
        std::fprintf(stderr, "pathlab bench: --simd: expected auto, avx512, avx2, sse4 or scalar, got '%s'\n", argv[i] + 7);
        return 1;
      }
      simd = t;
    }
    else if (std::strncmp(argv[i], "--spp=", 6) == 0)
      s.spp = std::max(1, std::atoi(argv[i] + 6));
    else if (std::strncmp(argv[i], "--waves=", 8) == 0) {
      s.waves.clear();
      for (const char* p = argv[i] + 8; *p != '\0';) {
        char* end = nullptr;
        const long w = std::strtol(p, &end, 10);
        if (end == p || w <= 0) {
          std::fprintf(stderr, "pathlab bench: --waves: expected positive wave sizes separated by commas, got '%s'\n",
                       argv[i] + 8);
          return 1;
        }
        s.waves.push_back(static_cast<std::size_t>(w));
        p = *end == ',' ? end + 1 : end;
      }
    }
    else if (std::strncmp(argv[i], "--modes=", 8) == 0) {
      for (const std::string& triple : split(argv[i] + 8, ',')) {
        const std::optional<WavefrontRayModes> m = parse_mode_triple(triple);
        if (!m) {
          std::fprintf(stderr,
                       "pathlab bench: --modes: expected CAMERA/BOUNCE/SHADOW triples of single, packet16 or stream "
                       "separated by commas, got '%s'\n",
                       argv[i] + 8);
          return 1;
        }
        s.modes.push_back(*m);
      }
    }
    else
      rest.push_back(argv[i]);
  }
  int rest_argc = static_cast<int>(rest.size());
  benchmark::Initialize(&rest_argc, rest.data());
  try {
    select_simd_target(simd, "--simd");
    Scene scene = load_scene(s.scene_file);
    scene.render.spp = s.spp;
    if (s.width > 0 && s.height > 0) scene.film.width = s.width, scene.film.height = s.height;
    s.settings = scene.render;
    s.scene = std::make_unique<CompiledScene>(std::move(scene));
    std::fprintf(stderr, "pathlab bench: %s, %dx%d, %d spp, %s, max depth %d\n", s.scene_file.c_str(),
                 s.scene->scene().film.width, s.scene->scene().film.height, s.spp,
                 strategy_name(s.settings.strategy), s.settings.max_depth);
    s.rays = capture_rays(*s.scene, s.settings);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pathlab bench: %s\n", e.what());
    return 1;
  }
  const std::string cpu = processor();
  benchmark::AddCustomContext("processor", cpu);
  std::fprintf(stderr, "pathlab bench: processor %s\n", cpu.c_str());
  benchmark::AddCustomContext("simd", simd_target_name(active_simd_target()));
  std::fprintf(stderr, "pathlab bench: SIMD target %s (--simd=NAME or PATHLAB_SIMD to choose)\n",
               simd_target_name(active_simd_target()));
  register_benchmarks();
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
