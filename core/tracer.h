// What the render driver needs of a tracer. Both tracers implement it over
// the same CompiledScene and RenderSettings and the same sample contract
// (rng.h, sample_dims.h).
#pragma once

#include "core/compiled_scene.h"
#include "core/film.h"
#include "core/path_observer.h"
#include "core/scene.h"

#include <cstdint>
#include <span>
#include <string_view>

namespace pathlab {

class Tracer {
 public:
  Tracer(const CompiledScene& scene, const RenderSettings& settings)
      : scene_(scene),
        settings_(settings),
        sampler_(settings.sampler, settings.seed, static_cast<std::uint32_t>(scene.scene().film.width),
                 static_cast<std::uint32_t>(scene.scene().film.height),
                 static_cast<std::uint32_t>(settings.spp > 1 ? settings.spp : 1)) {}
  virtual ~Tracer() = default;

  virtual std::string_view name() const = 0;

  // Traces samples [first, first + count) of every pixel into
  // out[pixel * count + j] (pixel = y * width + x), writing every field of
  // every element: `out` may arrive unwritten (SampleBuffer). May run in
  // parallel.
  virtual void render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const = 0;

  // Traces one sample of one pixel on the calling thread, reporting every
  // event to `observer` (which may be null).
  virtual FilmSample trace_sample(std::uint32_t x, std::uint32_t y, std::uint32_t sample,
                                  PathObserver* observer) const = 0;

  const CompiledScene& scene() const { return scene_; }
  const RenderSettings& settings() const { return settings_; }
  // The random numbers of one pixel sample, as both tracers draw them.
  SampleStream stream(std::uint32_t x, std::uint32_t y, std::uint32_t sample) const {
    return sampler_.stream(x, y, sample);
  }
  const SamplerSetup& sampler() const { return sampler_; }

 protected:
  const CompiledScene& scene_;
  RenderSettings settings_;
  SamplerSetup sampler_;  // made from settings_ and the film
};

}  // namespace pathlab
