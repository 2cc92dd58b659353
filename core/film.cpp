#include "core/film.h"

#include "core/parallel.h"

namespace pathlab {

Film::Film(int width, int height, FilterKind filter)
    : width_(width), height_(height), filter_(filter), pixels_(static_cast<std::size_t>(width) * height) {}

void Film::accumulate(Pixel& px, double w, const Spectrum& L) {
  const dvec3 l(L);
  const double w2 = w * w;
  px.sum_w += w;
  px.sum_w2 += w2;
  px.sum_wL += w * l;
  px.sum_w2L += w2 * l;
  px.sum_w2L2 += w2 * l * l;
}

void Film::add_batch(std::uint32_t first, std::uint32_t count, std::span<const FilmSample> samples) {
  const std::size_t n = samples.size();
  // Serial scan for bad samples: cheap, and it keeps the report in a fixed order.
  bad_mask_.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (is_finite(samples[i].L)) continue;
    bad_mask_[i] = 1;
    ++bad_count_;
    if (bad_kept_.size() < kMaxBadSamplesKept) {
      const std::size_t pixel = i / count;
      bad_kept_.push_back({static_cast<std::uint32_t>(pixel % width_), static_cast<std::uint32_t>(pixel / width_),
                           first + static_cast<std::uint32_t>(i % count), samples[i].L});
    }
  }

  parallel_for(0, static_cast<std::size_t>(height_), 1, [&](std::size_t y0, std::size_t y1) {
    for (int y = static_cast<int>(y0); y < static_cast<int>(y1); ++y) {
      for (int x = 0; x < width_; ++x) {
        Pixel& px = pixels_[static_cast<std::size_t>(y) * width_ + x];
        const std::size_t own = static_cast<std::size_t>(y) * width_ + x;
        for (std::uint32_t j = 0; j < count; ++j) {
          if (!bad_mask_[own * count + j]) ++px.count;
          if (filter_ == FilterKind::Box) {
            if (!bad_mask_[own * count + j]) accumulate(px, 1.0, samples[own * count + j].L);
            continue;
          }
          // Bilinear splat: gather sample j of the 3x3 source pixels around
          // (x, y), weighting each by the tent centred on this pixel's centre.
          const float cx = static_cast<float>(x) + 0.5f, cy = static_cast<float>(y) + 0.5f;
          for (int sy = std::max(0, y - 1); sy <= std::min(height_ - 1, y + 1); ++sy) {
            for (int sx = std::max(0, x - 1); sx <= std::min(width_ - 1, x + 1); ++sx) {
              const std::size_t i = (static_cast<std::size_t>(sy) * width_ + sx) * count + j;
              if (bad_mask_[i]) continue;
              const FilmSample& s = samples[i];
              const float wx = 1.0f - std::abs(s.film.x - cx), wy = 1.0f - std::abs(s.film.y - cy);
              if (wx <= 0.0f || wy <= 0.0f) continue;
              accumulate(px, static_cast<double>(wx) * wy, s.L);
            }
          }
        }
      }
    }
  });
}

Spectrum Film::mean(int x, int y) const {
  const Pixel& p = at(x, y);
  return p.sum_w > 0.0 ? Spectrum(p.sum_wL / p.sum_w) : Spectrum(0.0f);
}

Spectrum Film::variance_of_mean(int x, int y) const {
  const Pixel& p = at(x, y);
  if (p.sum_w <= 0.0) return Spectrum(0.0f);
  const dvec3 m = p.sum_wL / p.sum_w;
  // sum w^2 (L - m)^2 = sum w^2 L^2 - 2 m sum w^2 L + m^2 sum w^2
  const dvec3 ss = p.sum_w2L2 - 2.0 * m * p.sum_w2L + m * m * p.sum_w2;
  // With weights w = 1 this is the biased sample variance times n / n^2;
  // rescale by n/(n-1) (with n the effective sample size) to remove the bias.
  const double n_eff = p.sum_w * p.sum_w / p.sum_w2;
  const double bessel = n_eff > 1.0 ? n_eff / (n_eff - 1.0) : 0.0;
  return Spectrum(glm::max(ss, dvec3(0.0)) * (bessel / (p.sum_w * p.sum_w)));
}

Image Film::image() const {
  Image img(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) img.at(x, y) = mean(x, y);
  return img;
}

Image Film::variance_of_mean() const {
  Image img(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) img.at(x, y) = variance_of_mean(x, y);
  return img;
}

}  // namespace pathlab
