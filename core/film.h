// The film: per-pixel sums from which the image and its per-pixel variance
// follow. Samples arrive in batches laid out pixel-major
// (samples[pixel * count + j] is sample first + j of that pixel) and are
// gathered into each target pixel in a fixed order, sample index first, then
// neighbour, so the sums - and the image bits - are the same for any number
// of threads and any batch size.
//
// A pixel's estimate is the weighted mean  I = sum(w L) / sum(w),  a ratio
// estimator when the filter splats (bilinear); its variance is estimated by
// the delta method,  Var(I) ~= sum(w^2 (L - I)^2) / (sum w)^2,  which reduces
// to the usual  s^2 / n  for the box filter (w = 1).
#pragma once

#include "core/image_io.h"
#include "core/math.h"
#include "core/scene.h"

#include <cstdint>
#include <span>
#include <vector>

namespace pathlab {

// One traced sample: where on the film it lies and what it carried.
struct FilmSample {
  vec2 film{0.0f};          // position in pixels, (0,0) = top-left corner
  Spectrum L{0.0f};         // radiance estimate
  std::uint32_t rays = 0;   // rays it cast (camera, continuation, shadow)
  std::uint32_t hits = 0;   // surfaces the path reached (its length in vertices)
};

// A sample left out of the image because its radiance was NaN or infinite.
struct BadSample {
  std::uint32_t x = 0, y = 0, sample = 0;
  Spectrum L{0.0f};
};

class Film {
 public:
  Film(int width, int height, FilterKind filter);

  int width() const { return width_; }
  int height() const { return height_; }
  FilterKind filter() const { return filter_; }

  // Adds samples [first, first + count) of every pixel. NaN / Inf samples are
  // left out, counted and remembered (the first kMaxBadSamplesKept).
  void add_batch(std::uint32_t first, std::uint32_t count, std::span<const FilmSample> samples);

  Image image() const;                  // the per-pixel weighted mean
  Image variance_of_mean() const;       // estimated variance of that mean
  Spectrum mean(int x, int y) const;
  Spectrum variance_of_mean(int x, int y) const;
  // Samples that fell in pixel (x, y) (its own samples, not splat neighbours).
  std::uint64_t sample_count(int x, int y) const { return at(x, y).count; }

  std::uint64_t bad_sample_count() const { return bad_count_; }
  const std::vector<BadSample>& bad_samples() const { return bad_kept_; }
  static constexpr std::size_t kMaxBadSamplesKept = 16;

 private:
  struct Pixel {
    double sum_w = 0.0;
    double sum_w2 = 0.0;
    dvec3 sum_wL{0.0};
    dvec3 sum_w2L{0.0};
    dvec3 sum_w2L2{0.0};
    std::uint64_t count = 0;
  };
  const Pixel& at(int x, int y) const { return pixels_[static_cast<std::size_t>(y) * width_ + x]; }
  void accumulate(Pixel& px, double w, const Spectrum& L);

  int width_, height_;
  FilterKind filter_;
  std::vector<Pixel> pixels_;
  std::uint64_t bad_count_ = 0;
  std::vector<BadSample> bad_kept_;
  std::vector<std::uint8_t> bad_mask_;  // scratch for one batch
};

}  // namespace pathlab
