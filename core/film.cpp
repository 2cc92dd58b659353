#include "core/film.h"

#include "core/parallel.h"

#include <algorithm>
#include <stdexcept>
#include <tuple>

namespace pathlab {

static_assert(sizeof(Sum1) == 16 && sizeof(Sum2) == 16);


Film::Film(int width, int height, FilterKind filter, FilmMoments moments)
    : width_(width),
      height_(height),
      filter_(filter),
      moments_(moments),
      pixels_(static_cast<std::size_t>(width) * height),
      moments_sums_(moments == FilmMoments::Mean ? 0 : static_cast<std::size_t>(width) * height),
      splat_(filter == FilterKind::Box ? 0 : static_cast<std::size_t>(width) * height) {
  // Zeroed in parallel: at 720p with the variance (52 MB) that takes 9-10 ms
  // on two threads, against 14 ms for the vectors zeroing them on one.
  parallel_for(0, pixels_.size(), std::size_t{1} << 16, [&](std::size_t b, std::size_t e) {
    const auto from = static_cast<std::ptrdiff_t>(b), to = static_cast<std::ptrdiff_t>(e);
    std::fill(pixels_.begin() + from, pixels_.begin() + to, Pixel{});
    if (!moments_sums_.empty()) std::fill(moments_sums_.begin() + from, moments_sums_.begin() + to, Moments{});
    if (!splat_.empty()) std::fill(splat_.begin() + from, splat_.begin() + to, SplatSums{});
  });
}

void Film::add_batch(std::uint32_t first, std::uint32_t count, std::span<const FilmSample> samples) {
  // One parallel pass over the rows; each pixel gathers its samples (the
  // order no longer matters to the sums, which are exact, but it keeps each
  // pixel's memory on one thread). Bad samples are left out and counted per row; a batch
  // that had any is scanned again, serially, to report them in order. The
  // rows' rays are summed on the way.
  struct RowTally {
    std::uint64_t bad, rays;
  };
  std::vector<RowTally> tally(static_cast<std::size_t>(height_));
  const bool variance = keeps_variance();
  parallel_for(0, static_cast<std::size_t>(height_), 1, [&](std::size_t y0, std::size_t y1) {
    for (int y = static_cast<int>(y0); y < static_cast<int>(y1); ++y) {
      std::uint64_t bad = 0, rays = 0;
      for (int x = 0; x < width_; ++x) {
        Pixel& px = pixels_[index(x, y)];
        Moments* const moments = variance ? &moments_sums_[index(x, y)] : nullptr;
        const std::size_t own = index(x, y) * count;
        for (std::uint32_t j = 0; j < count; ++j) rays += samples[own + j].rays;
        if (filter_ == FilterKind::Box) {
          for (std::uint32_t j = 0; j < count; ++j) {
            const Spectrum& L = samples[own + j].L;
            if (!in_film_range(L)) {
              ++bad;
              continue;
            }
            ++px.count;
            for (int c = 0; c < 3; ++c) px.sum_wL[c].add(L[c]);
            if (!moments) continue;
            for (int c = 0; c < 3; ++c) moments->sum_w2L2[c].add(static_cast<double>(L[c]) * L[c]);
          }
          continue;
        }
        // Bilinear splat: gather sample j of the 3x3 source pixels around
        // (x, y), weighting each by the tent centred on this pixel's centre.
        SplatSums& sp = splat_[index(x, y)];
        const float cx = static_cast<float>(x) + 0.5f, cy = static_cast<float>(y) + 0.5f;
        for (std::uint32_t j = 0; j < count; ++j) {
          if (in_film_range(samples[own + j].L))
            ++px.count;
          else
            ++bad;
          for (int sy = std::max(0, y - 1); sy <= std::min(height_ - 1, y + 1); ++sy) {
            for (int sx = std::max(0, x - 1); sx <= std::min(width_ - 1, x + 1); ++sx) {
              const FilmSample& s = samples[index(sx, sy) * count + j];
              if (!in_film_range(s.L)) continue;
              const float wx = 1.0f - std::abs(s.film.x - cx), wy = 1.0f - std::abs(s.film.y - cy);
              if (wx <= 0.0f || wy <= 0.0f) continue;
              const double w = static_cast<double>(wx) * wy;
              const dvec3 l(s.L);
              sp.sum_w.add(w);
              for (int c = 0; c < 3; ++c) px.sum_wL[c].add(w * l[c]);
              if (!moments) continue;
              const double w2 = w * w;
              sp.sum_w2.add(w2);
              for (int c = 0; c < 3; ++c) {
                sp.sum_w2L[c].add(w2 * l[c]);
                moments->sum_w2L2[c].add(w2 * l[c] * l[c]);
              }
            }
          }
        }
      }
      tally[static_cast<std::size_t>(y)] = {bad, rays};
    }
  });
  std::uint64_t bad = 0;
  for (const RowTally& t : tally) {
    bad += t.bad;
    rays_ += t.rays;
  }
  if (bad > 0) {
    bad_count_ += bad;
    record_bad(first, count, samples);
  }
}

void Film::record_bad(std::uint32_t first, std::uint32_t count, std::span<const FilmSample> samples) {
  std::vector<BadSample> found;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (in_film_range(samples[i].L)) continue;
    const std::size_t pixel = i / count;
    found.push_back({static_cast<std::uint32_t>(pixel % width_), static_cast<std::uint32_t>(pixel / width_),
                     first + static_cast<std::uint32_t>(i % count), samples[i].L});
  }
  keep_bad(std::move(found));
}

// The bad samples kept are the first kMaxBadSamplesKept in the order (sample,
// row, column): the same ones however the samples were split.
void Film::keep_bad(std::vector<BadSample> more) {
  bad_kept_.insert(bad_kept_.end(), more.begin(), more.end());
  const auto key = [](const BadSample& b) { return std::tuple(b.sample, b.y, b.x); };
  std::sort(bad_kept_.begin(), bad_kept_.end(), [&](const BadSample& a, const BadSample& b) { return key(a) < key(b); });
  bad_kept_.erase(std::unique(bad_kept_.begin(), bad_kept_.end(),
                              [&](const BadSample& a, const BadSample& b) { return key(a) == key(b); }),
                  bad_kept_.end());
  if (bad_kept_.size() > kMaxBadSamplesKept) bad_kept_.resize(kMaxBadSamplesKept);
}

void Film::add_pixel_words(const std::uint64_t* in, std::uint64_t* inout, std::size_t pixels) {
  for (std::size_t i = 0; i < pixels; ++i, in += kPixelWords, inout += kPixelWords) {
    add_sum_words(in, inout, 3);
    inout[6] += in[6];  // the count
  }
}

void Film::add_sum_words(const std::uint64_t* in, std::uint64_t* inout, std::size_t sums) {
  for (std::size_t i = 0; i < 2 * sums; i += 2) {
    Sum1 a = Sum1::from_words(inout[i], inout[i + 1]);
    a += Sum1::from_words(in[i], in[i + 1]);
    inout[i] = a.low();
    inout[i + 1] = a.high();
  }
}

void Film::add(const Film& o) {
  if (o.width_ != width_ || o.height_ != height_ || o.filter_ != filter_ || o.moments_ != moments_)
    throw std::invalid_argument("Film::add: the films differ in size, filter or moments");
  const Words mine = words();
  const ConstWords theirs = o.words();
  // Every sum is a 128-bit integer (Sum2's units differ from Sum1's, but
  // adding raw words is the same operation).
  parallel_for(0, pixels_.size(), std::size_t{1} << 14, [&](std::size_t b, std::size_t e) {
    add_pixel_words(theirs.pixels.data() + b * kPixelWords, mine.pixels.data() + b * kPixelWords, e - b);
    if (!moments_sums_.empty())
      add_sum_words(theirs.moments.data() + b * kMomentWords, mine.moments.data() + b * kMomentWords, 3 * (e - b));
    if (!splat_.empty())
      add_sum_words(theirs.splat.data() + b * kSplatWords, mine.splat.data() + b * kSplatWords, 5 * (e - b));
  });
  bad_count_ += o.bad_count_;
  rays_ += o.rays_;
  keep_bad(o.bad_kept_);
}

Film::Words Film::words() {
  static_assert(sizeof(Pixel) == kPixelWords * 8 && sizeof(Moments) == kMomentWords * 8 &&
                sizeof(SplatSums) == kSplatWords * 8);
  static_assert(alignof(Pixel) == 8 && alignof(Moments) == 8 && alignof(SplatSums) == 8);
  const auto as_words = [](auto& v) {
    return std::span<std::uint64_t>(reinterpret_cast<std::uint64_t*>(v.data()), v.size() * sizeof(v[0]) / 8);
  };
  return {as_words(pixels_), as_words(moments_sums_), as_words(splat_)};
}

Film::ConstWords Film::words() const {
  const Words w = const_cast<Film*>(this)->words();
  return {w.pixels, w.moments, w.splat};
}

void Film::restore_counts(std::uint64_t bad, std::uint64_t rays, std::vector<BadSample> kept) {
  bad_count_ = bad;
  rays_ = rays;
  bad_kept_.clear();
  keep_bad(std::move(kept));
}

namespace {
template <class S>
dvec3 value(const S (&sums)[3]) {
  return {sums[0].value(), sums[1].value(), sums[2].value()};
}
}  // namespace

Film::Sums Film::sums(int x, int y) const {
  const Pixel& p = pixels_[index(x, y)];
  const dvec3 sum_w2L2 = keeps_variance() ? value(moments_sums_[index(x, y)].sum_w2L2) : dvec3(0.0);
  const dvec3 sum_wL = value(p.sum_wL);
  if (filter_ == FilterKind::Box) {
    const auto n = static_cast<double>(p.count);
    return {n, n, sum_wL, sum_wL, sum_w2L2};
  }
  const SplatSums& s = splat_[index(x, y)];
  return {s.sum_w.value(), s.sum_w2.value(), sum_wL, value(s.sum_w2L), sum_w2L2};
}

void Film::require_variance() const {
  if (!keeps_variance())
    throw std::logic_error("Film::variance_of_mean: the film was made with FilmMoments::Mean and keeps no variance");
}

Spectrum Film::mean(int x, int y) const {
  // sums(x, y) without the second moments, which image() need not read.
  const Pixel& p = pixels_[index(x, y)];
  const double sum_w = filter_ == FilterKind::Box ? static_cast<double>(p.count) : splat_[index(x, y)].sum_w.value();
  return sum_w > 0.0 ? Spectrum(value(p.sum_wL) / sum_w) : Spectrum(0.0f);
}

Spectrum Film::variance_of_mean(int x, int y) const {
  require_variance();
  const Sums p = sums(x, y);
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
  parallel_for(0, static_cast<std::size_t>(height_), 16, [&](std::size_t y0, std::size_t y1) {
    for (int y = static_cast<int>(y0); y < static_cast<int>(y1); ++y)
      for (int x = 0; x < width_; ++x) img.at(x, y) = mean(x, y);
  });
  return img;
}

Image Film::variance_of_mean() const {
  require_variance();
  Image img(width_, height_);
  parallel_for(0, static_cast<std::size_t>(height_), 16, [&](std::size_t y0, std::size_t y1) {
    for (int y = static_cast<int>(y0); y < static_cast<int>(y1); ++y)
      for (int x = 0; x < width_; ++x) img.at(x, y) = variance_of_mean(x, y);
  });
  return img;
}

}  // namespace pathlab
