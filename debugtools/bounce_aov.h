// The per-bounce decomposition of a render (`render --aov bounces`,
// docs/aov.md): the radiance each sample gathered, split by the depth of
// the path that brought it and by the technique that found the light.
//
//   depth d     the number of scattering vertices on the path from the camera
//               to the light: emission seen directly is depth 0; emission a
//               ray finds at vertex v (the camera ray's hit, or a
//               continuation ray's) and the environment it escapes to are
//               depth v - 1; a light sample (NEE) taken at vertex v is
//               depth v. So both techniques of one path length land in one
//               depth, and their MIS weights sum to 1 there.
//   technique   `bsdf`: emission found by a ray (camera ray, BSDF or cosine
//               continuation, an escape); `nee`: next-event estimation (area,
//               environment and delta lights). Each is the event's `added`:
//               throughput x MIS or strategy weight x radiance.
//
// Depths 0 .. kBounceDepths - 1 have layers of their own; deeper paths go to
// the `rest` layer, so the layers of a sample sum to its radiance (up to the
// float rounding of the tracers' own sums).
//
// Built only on PathObserver events (core/path_observer.h): a render with
// the layers traces every sample through Tracer::trace_sample with an
// observer (the wavefront's scalar stages, one path per wave); a render
// without them is not touched.
#pragma once

#include "core/image_io.h"
#include "core/path_observer.h"
#include "core/tracer.h"

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pathlab {

inline constexpr int kBounceDepths = 8;                 // L0 .. L7
inline constexpr int kBounceLayers = kBounceDepths + 1;  // and `rest`
enum class Technique : std::uint8_t { Bsdf, Nee };
inline constexpr int kTechniques = 2;
const char* technique_name(Technique t);  // "bsdf", "nee"
// "L0" .. "L7", "Lrest"
std::string bounce_layer_name(int depth);

// One sample's radiance by [depth layer][technique].
struct BounceLayers {
  std::array<std::array<Spectrum, kTechniques>, kBounceLayers> L{};
  void add(int depth, Technique t, const Spectrum& added) {
    L[static_cast<std::size_t>(std::min(depth, kBounceDepths))][static_cast<std::size_t>(t)] += added;
  }
  Spectrum total() const;
};

// Sorts one path's contributions into layers.
class BounceObserver final : public PathObserver {
 public:
  void on_hit(const HitEvent& e) override { layers.add(e.vertex - 1, Technique::Bsdf, e.added); }
  void on_escape(const EscapeEvent& e) override { layers.add(e.vertex - 1, Technique::Bsdf, e.added); }
  void on_light(const LightEvent& e) override { layers.add(e.vertex, Technique::Nee, e.added); }
  BounceLayers layers;
};

// Per pixel and layer: the sum and the sum of squares of the samples'
// values (box average over the pixel's own samples, as the other AOVs).
class BounceAccumulator {
 public:
  BounceAccumulator(int width, int height);
  // Sample of pixel `pixel` (y * width + x). Pixels may be added from
  // different threads; one pixel from one thread at a time.
  void add(std::size_t pixel, const BounceLayers& layers);
  // Adds another accumulator's sums (same size).
  void add(const BounceAccumulator& other);

  int width() const { return width_; }
  int height() const { return height_; }
  // Mean of the layer over the pixel's samples, and its estimated variance
  // of that mean (sample variance / n; 0 with fewer than 2 samples).
  Image mean(int depth, Technique t) const;
  Image variance_of_mean(int depth, Technique t) const;
  std::uint64_t samples(std::size_t pixel) const { return count_[pixel]; }

  // Raw sums, for files (compare --export).
  struct Sums {
    dvec3 sum{0.0}, sum_sq{0.0};
  };
  const Sums& sums(std::size_t pixel, int depth, Technique t) const {
    return sums_[index(pixel, depth, t)];
  }
  void set(std::size_t pixel, std::uint64_t count, int depth, Technique t, const Sums& s) {
    count_[pixel] = count;
    sums_[index(pixel, depth, t)] = s;
  }

 private:
  std::size_t index(std::size_t pixel, int depth, Technique t) const {
    return (pixel * kBounceLayers + static_cast<std::size_t>(depth)) * kTechniques + static_cast<std::size_t>(t);
  }
  int width_, height_;
  std::vector<Sums> sums_;
  std::vector<std::uint64_t> count_;
};

// Forwards to `inner`, but renders each batch sample by sample through
// inner.trace_sample with a BounceObserver, and adds the layers to
// `bounces`. The FilmSamples are trace_sample's, which are the bits
// render_batch gives (both tracers; the wavefront's scalar and vectorised
// stages agree bit for bit).
class BounceTracer final : public Tracer {
 public:
  BounceTracer(const Tracer& inner, BounceAccumulator& bounces)
      : Tracer(inner.scene(), inner.settings()), inner_(inner), bounces_(bounces) {}
  std::string_view name() const override { return inner_.name(); }
  void render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const override;
  FilmSample trace_sample(std::uint32_t x, std::uint32_t y, std::uint32_t sample, PathObserver* observer) const override {
    return inner_.trace_sample(x, y, sample, observer);
  }

 private:
  const Tracer& inner_;
  BounceAccumulator& bounces_;
};

// The EXR layers "L<d>.bsdf.{R,G,B}", "L<d>.nee.{R,G,B}" for d = 0 .. 7 and
// "Lrest.bsdf", "Lrest.nee": the per-pixel means.
void add_bounce_channels(std::vector<ExrChannel>& out, const BounceAccumulator& bounces);

}  // namespace pathlab
