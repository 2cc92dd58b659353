// Auxiliary buffers (AOVs) of a render, computed beside any tracer: a
// camera-ray pass over the same camera samples the tracer used (the film and
// lens dimensions of core/sample_dims.h) gives the first surface of each
// sample, and the tracer's FilmSamples give the path lengths. Per pixel:
//
//   albedo      mean over the pixel's own samples of the first surface's
//               albedo (reflectance; 0 for a surface that does not scatter
//               and for samples that escape)
//   normal      mean shading normal of the first surface (world space, not
//               renormalised; 0 where every sample escaped)
//   depth       mean distance along the camera ray to the first surface, over
//               the samples that hit one (0 where none did)
//   material    index of the material sample 0 of the pixel hit (-1: none)
//   pathlength  mean FilmSample::hits: surfaces the path reached
//   nonfinite   samples whose radiance was NaN or infinite (left out of the film)
//
// Means are box averages over the pixel's own samples (not the film's
// filter), so a bilinear-filtered beauty image and its AOVs differ by the
// filter's blur. See docs/aov.md.
#pragma once

#include "core/compiled_scene.h"
#include "core/film.h"
#include "core/image_io.h"
#include "core/tracer.h"

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab {

class BounceAccumulator;

// Bounces: the per-bounce decomposition (debugtools/bounce_aov.h), which
// needs its own pass (BounceTracer); the others come from AovAccumulator.
enum class Aov : std::uint8_t { Albedo, Normal, Depth, Material, Variance, PathLength, Bounces };
inline constexpr Aov kAllAovs[] = {Aov::Albedo,   Aov::Normal,     Aov::Depth,  Aov::Material,
                                   Aov::Variance, Aov::PathLength, Aov::Bounces};
// The layers AovAccumulator gathers by itself, alongside any render (the
// GUI's progressive render shows these; Bounces needs a BounceTracer pass).
inline constexpr Aov kAccumulatedAovs[] = {Aov::Albedo,   Aov::Normal,   Aov::Depth,
                                           Aov::Material, Aov::Variance, Aov::PathLength};
const char* aov_name(Aov a);  // "albedo", "normal", "depth", "material", "variance", "pathlength", "bounces"
std::optional<Aov> parse_aov(std::string_view name);

class AovAccumulator {
 public:
  AovAccumulator(const CompiledScene& scene, const RenderSettings& settings);

  // Adds samples [first, first + count) of every pixel: `samples` is the
  // tracer's output for them (pixel-major, as Tracer::render_batch).
  void add_batch(std::uint32_t first, std::uint32_t count, std::span<const FilmSample> samples);

  int width() const { return width_; }
  int height() const { return height_; }
  Image albedo() const;
  Image normal() const;
  Image depth() const;        // one value, replicated in x, y, z
  Image material() const;     // one value, replicated
  Image path_length() const;  // one value, replicated
  Image nonfinite() const;    // one value, replicated

  // Single pixels, for a viewer's readout.
  float path_length(int x, int y) const;
  std::uint64_t nonfinite(int x, int y) const;

 private:
  struct Pixel {
    dvec3 albedo{0.0}, normal{0.0};
    double depth = 0.0;
    std::uint64_t samples = 0, surface_hits = 0, path_hits = 0, nonfinite = 0;
    int material = -1;
  };
  template <typename F>
  Image map(F&& f) const;

  const CompiledScene& scene_;
  RenderSettings settings_;
  int width_, height_;
  std::vector<Pixel> pixels_;
};

// Forwards to `inner` and adds every batch it renders to `aovs`: the render
// driver (core/render.h) fills the film and the AOVs in one pass.
class AovTracer final : public Tracer {
 public:
  AovTracer(const Tracer& inner, AovAccumulator& aovs)
      : Tracer(inner.scene(), inner.settings()), inner_(inner), aovs_(aovs) {}
  std::string_view name() const override { return inner_.name(); }
  void render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const override {
    inner_.render_batch(first, count, out);
    aovs_.add_batch(first, count, out);
  }
  FilmSample trace_sample(std::uint32_t x, std::uint32_t y, std::uint32_t sample, PathObserver* observer) const override {
    return inner_.trace_sample(x, y, sample, observer);
  }

 private:
  const Tracer& inner_;
  AovAccumulator& aovs_;
};

// Appends image's first channels.size() components as the channels
// "<layer>.<c>" for each letter c of `channels` ("<c>" alone if `layer` is
// empty): add_exr_layer(out, "normal", n, "XYZ") adds normal.X, normal.Y, normal.Z.
void add_exr_layer(std::vector<ExrChannel>& out, const std::string& layer, const Image& image, std::string_view channels);

// The EXR channels of the beauty image (R, G, B) followed by the requested
// AOVs as named layers: albedo.{R,G,B}, normal.{X,Y,Z}, depth.Z, material.Y,
// variance.{R,G,B} (the film's variance of the pixel mean), pathlength.Y,
// and for `bounces` the layers of `bounces` (add_bounce_channels; required then).
std::vector<ExrChannel> aov_channels(const Film& film, const AovAccumulator& aovs, std::span<const Aov> which,
                                     const BounceAccumulator* bounces = nullptr);

}  // namespace pathlab
