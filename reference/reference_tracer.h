// The reference tracer: the classic recursive path tracer, L_i(ray), kept
// short so it can be read as the definition of what pathlab computes. The
// wavefront tracer must agree with it path by path.
#pragma once

#include "core/strategy_weights.h"
#include "core/tracer.h"

namespace pathlab {

class ReferenceTracer final : public Tracer {
 public:
  using Tracer::Tracer;

  std::string_view name() const override { return "reference"; }
  void render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const override;
  FilmSample trace_sample(std::uint32_t x, std::uint32_t y, std::uint32_t sample,
                          PathObserver* observer) const override;

 private:
  struct Path;
  Spectrum Li(const Ray& ray, int vertex, const PreviousVertex& prev, const Spectrum& beta, Path& path) const;
  Spectrum direct_delta(const Surfel& s, const vec3& wo, int vertex, const Spectrum& beta, Path& path) const;
  Spectrum direct_area(const Surfel& s, const vec3& wo, int vertex, const Spectrum& beta, Path& path) const;
};

}  // namespace pathlab
