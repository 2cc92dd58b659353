#include "core/render.h"

#include <algorithm>
#include <chrono>
#include <vector>

namespace pathlab {
namespace {

// pbrt-style firefly clamp: scale a finite sample down so that its largest
// component is `limit`, keeping its colour. Biased: off unless asked for.
// Non-finite samples pass through untouched (the film counts and locates them).
void clamp_samples(std::span<FilmSample> out, float limit, RenderStats& stats) {
  for (FilmSample& s : out) {
    if (!is_finite(s.L)) continue;
    const double before = average(s.L);
    stats.energy_total += before;
    const float m = max_component(s.L);
    if (m > limit) {
      s.L *= limit / m;
      ++stats.clamped_samples;
      stats.energy_clamped += before - average(s.L);
    }
  }
}

}  // namespace

std::uint32_t batch_size(int width, int height, int spp) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(width) * height;
  const std::uint64_t per_batch = std::max<std::uint64_t>(1, (std::uint64_t{1} << 18) / std::max<std::uint64_t>(pixels, 1));
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(per_batch, static_cast<std::uint64_t>(std::max(spp, 1))));
}

RenderStats render(const Tracer& tracer, Film& film, const ProgressFn& progress) {
  const auto start = std::chrono::steady_clock::now();
  const int spp = tracer.settings().spp;
  const std::uint32_t batch = batch_size(film.width(), film.height(), spp);
  const std::size_t pixels = static_cast<std::size_t>(film.width()) * film.height();
  std::vector<FilmSample> samples(pixels * batch);
  RenderStats stats;
  for (std::uint32_t first = 0; first < static_cast<std::uint32_t>(spp); first += batch) {
    const std::uint32_t count = std::min<std::uint32_t>(batch, static_cast<std::uint32_t>(spp) - first);
    const std::span<FilmSample> out(samples.data(), pixels * count);
    tracer.render_batch(first, count, out);
    if (tracer.settings().clamp > 0.0f) clamp_samples(out, tracer.settings().clamp, stats);
    film.add_batch(first, count, out);
    for (const FilmSample& s : out) stats.rays += s.rays;
    stats.samples += out.size();
    if (progress) progress(static_cast<double>(first + count) / spp);
  }
  stats.bad_samples = film.bad_sample_count();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace pathlab
