// Comparing two tracers (or two builds of one) at the same seed: the rule
// the same-seed tests apply, as a library for `pathlab compare`
// (docs/compare.md) and for tests/test_wavefront.cpp.
//
// Samples. Two samples agree if their radiance agrees within 1e-4 relative
// (plus 1e-6 absolute near 0) and they reached as many surfaces and cast as
// many rays. Two renders agree if at least 99.9 % of their samples agree
// and every sample that does not is explained: replayed with both, its
// paths agree event by event (first_divergence at 1e-3) up to where a
// floating-point difference flipped a decision. Samples are visited in a
// defined order, row-major pixel then sample index, so "the first
// disagreeing sample" is the same for any thread count.
//
// Bounces. The per-bounce layers of both (debugtools/bounce_aov.h) are
// compared per pixel, depth, technique and channel by z = (a - b) / s with
// s^2 = the larger variance of the mean over the pixel's 3x3 neighbourhood
// of a, plus that of b, plus a rounding floor (as analytic-scenes/check.cpp
// does; at the same seed the two are positively correlated, so this s
// overstates the difference's spread and the test is conservative), with a
// Šidák-corrected threshold over all those tests; and per layer and channel
// by the mean of a - b over the image against its standard error (Šidák over
// layers x techniques x channels). The first depth with a rejection is
// where the per-bounce images first disagree.
#pragma once

#include "core/tracer.h"
#include "debugtools/bounce_aov.h"
#include "debugtools/path_compare.h"
#include "debugtools/path_recorder.h"

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace pathlab {

inline constexpr float kSameSampleTolerance = 1e-4f;     // relative radiance
inline constexpr float kSameSampleAbsolute = 1e-6f;      // absolute, near 0
inline constexpr double kSameSeedShare = 0.999;          // of samples that must agree
inline constexpr float kReplayTolerance = 1e-3f;         // first_divergence on a disagreeing sample

// The same-seed rule for one sample.
bool same_sample(const FilmSample& a, const FilmSample& b);

struct SampleDisagreement {
  std::uint32_t x = 0, y = 0, sample = 0;
  FilmSample a, b;
  PathDivergence divergence;  // of the replayed paths (kReplayTolerance)
};

struct SampleComparison {
  std::size_t samples = 0, equal = 0;
  std::size_t differing() const { return samples - equal; }
  // The disagreeing samples that were replayed, in order (row-major pixel,
  // then sample): all of them while they are few enough for the render to
  // agree (at most 0.1 %), else only the first (the verdict is then
  // "disagree" anyway).
  std::vector<SampleDisagreement> replayed;
  std::size_t unexplained = 0;  // replayed ones whose divergence is not rounding
  bool agree() const {
    return static_cast<double>(equal) >= kSameSeedShare * static_cast<double>(samples) && unexplained == 0;
  }
};

// Replays sample (x, y, sample) with both sides and returns where their
// paths part.
using ReplayFn = std::function<PathDivergence(std::uint32_t x, std::uint32_t y, std::uint32_t sample)>;

// Gathers batches of both sides' samples, then replays disagreements in
// order. Keeps only the disagreeing samples, so a render may come in any
// number of batches.
class SampleComparer {
 public:
  // `total`: the samples both sides will hold in all (only the first
  // 0.1 % + 1 disagreements in order are kept: more cannot agree).
  SampleComparer(int width, std::size_t total)
      : width_(width), keep_(static_cast<std::size_t>((1.0 - kSameSeedShare) * static_cast<double>(total)) + 1) {}
  // a and b hold samples [first, first + count) of every pixel,
  // pixel-major (as Tracer::render_batch fills them).
  void add_batch(std::span<const FilmSample> a, std::span<const FilmSample> b, std::uint32_t count,
                 std::uint32_t first);
  SampleComparison finish(const ReplayFn& replay);

 private:
  void trim(std::size_t n);  // sorts the disagreements and keeps the first n
  int width_;
  std::size_t keep_;
  std::size_t samples_ = 0, equal_ = 0;
  std::vector<SampleDisagreement> differing_;  // not yet replayed
};

// One batch: samples [first, first + count) of every pixel of a width-pixel film.
SampleComparison compare_samples(std::span<const FilmSample> a, std::span<const FilmSample> b, int width,
                                 std::uint32_t count, std::uint32_t first, const ReplayFn& replay);

// Replays one sample with both tracers (PathRecorder) and compares the paths.
PathDivergence replay_divergence(const Tracer& a, const Tracer& b, std::uint32_t x, std::uint32_t y,
                                 std::uint32_t sample, float tolerance = kReplayTolerance);

// Renders samples [0, spp) of every pixel with both (render_batch, in
// batches of about 2^20 samples) and compares them, replaying
// disagreements with both.
SampleComparison compare_tracers(const Tracer& a, const Tracer& b, std::uint32_t spp);

struct BounceDeviation {
  int depth = 0;  // kBounceDepths: the rest layer
  Technique technique = Technique::Bsdf;
  int x = -1, y = -1, channel = 0;  // x = -1: the image-wide mean test
  double z = 0.0, a = 0.0, b = 0.0;
};

struct BounceComparison {
  double alpha = 1e-4;
  double pixel_threshold = 0.0, image_threshold = 0.0;  // Šidák-corrected |z|
  // Per layer (depth x technique): the most significant deviation and how
  // many pixel-channels were beyond the threshold.
  struct Layer {
    BounceDeviation worst_pixel, image;
    std::size_t failing_pixels = 0;
    bool disagree = false;
  };
  std::array<std::array<Layer, kTechniques>, kBounceLayers> layers{};
  // The first depth at which some technique disagrees (-1: none;
  // kBounceDepths: only the rest layer).
  int first_depth = -1;
  bool agree() const { return first_depth < 0; }
};

BounceComparison compare_bounces(const BounceAccumulator& a, const BounceAccumulator& b, double alpha = 1e-4);

// Renders samples [0, spp) of every pixel with the tracer's trace_sample and
// a BounceObserver.
BounceAccumulator render_bounces(const Tracer& tracer, std::uint32_t spp);

// The file `compare --export` writes and `compare --with` reads: one side of
// a comparison, made by one build. Binary, little-endian, versioned
// (docs/compare.md).
struct SampleExport {
  std::string tracer;
  int width = 0, height = 0;
  std::uint32_t spp = 0;
  std::uint64_t seed = 0;
  std::vector<FilmSample> samples;  // pixel-major, spp per pixel
  BounceAccumulator bounces{0, 0};
};
void write_sample_export(const std::string& file, const SampleExport& e);
// Throws InputError naming the file and what is wrong.
SampleExport read_sample_export(const std::string& file);

}  // namespace pathlab
