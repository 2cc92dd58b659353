#include "core/render.h"

#include <algorithm>
#include <chrono>
#include <vector>

namespace pathlab {

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
