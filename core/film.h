// The film: per-pixel sums from which the image and its per-pixel variance
// follow. Samples arrive in batches laid out pixel-major
// (samples[pixel * count + j] is sample first + j of that pixel) and are
// gathered into each target pixel in a fixed order, sample index first, then
// neighbour, so the sums - and the image bits - are the same for any number
// of threads and any batch size.
//
// The sums are fixed-point (core/fixed_sum.h), so they do not depend on the
// order samples arrive in either: a film rendered in pieces - resumed,
// merged from sample ranges, reduced over processes (add()) - has the same
// bits as one made in one go.
//
// A pixel's estimate is the weighted mean  I = sum(w L) / sum(w),  a ratio
// estimator when the filter splats (bilinear); its variance is estimated by
// the delta method,  Var(I) ~= sum(w^2 (L - I)^2) / (sum w)^2,  which reduces
// to the usual  s^2 / n  for the box filter (w = 1).
#pragma once

#include "core/fixed_sum.h"
#include "core/huge_pages.h"
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

// A sample left out of the image because its radiance was NaN, infinite or
// beyond the film's range (a component of magnitude kFilmRadianceLimit or
// more: 2^32, about 4.3e9).
struct BadSample {
  std::uint32_t x = 0, y = 0, sample = 0;
  Spectrum L{0.0f};
};

inline constexpr double kFilmRadianceLimit = Sum1::kLimit;
// The film rounds each sample to units of 2^-64 (Sum1): within 2^-65 of it,
// an absolute resolution. A scene whose brightest emitter is below this
// (2^-55, about 2.8e-17) loses more than 2^-10 of its light to the rounding,
// samples below 2^-65 vanish, and the CLI warns (docs/overnight.md).
inline constexpr double kFilmFaintRadiance = 0x1p-55;
// True if the film can add L: finite and every component below
// kFilmRadianceLimit (also false for NaN: every comparison with it is).
inline bool in_film_range(const Spectrum& L) {
  for (int c = 0; c < 3; ++c)
    if (!(std::abs(L[c]) < static_cast<float>(kFilmRadianceLimit))) return false;
  return true;
}

// What a film keeps beyond each pixel's weighted mean.
enum class FilmMoments : std::uint8_t {
  // Second moments too, for variance_of_mean() (the variance AOV, the
  // analytic checks, progressive rendering, which estimates its error from
  // them).
  MeanAndVariance,
  // The image alone, for a render that writes nothing else: a box pixel is
  // then 56 bytes instead of 104, which the film's pass over every batch
  // reads and writes (at 720p about half the memory traffic).
  Mean,
};

class Film {
 public:
  Film(int width, int height, FilterKind filter, FilmMoments moments = FilmMoments::MeanAndVariance);

  int width() const { return width_; }
  int height() const { return height_; }
  FilterKind filter() const { return filter_; }
  bool keeps_variance() const { return moments_ == FilmMoments::MeanAndVariance; }

  // Adds samples [first, first + count) of every pixel. Samples outside the
  // film's range (NaN, Inf, huge: in_film_range) are left out, counted and
  // remembered (the first kMaxBadSamplesKept by sample index, then row, then
  // column); the rays of every sample, bad or not, are summed into rays_cast().
  void add_batch(std::uint32_t first, std::uint32_t count, std::span<const FilmSample> samples);
  // Adds another film of the same size, filter and moments, which holds
  // other samples: the result has the bits of one film given both sets of
  // samples. Throws std::invalid_argument if the films do not match.
  void add(const Film& other);

  Image image() const;                  // the per-pixel weighted mean
  Spectrum mean(int x, int y) const;
  // The estimated variance of that mean. Throws std::logic_error unless the
  // film keeps_variance().
  Image variance_of_mean() const;
  Spectrum variance_of_mean(int x, int y) const;
  // Samples that fell in pixel (x, y) (its own samples, not splat neighbours).
  std::uint64_t sample_count(int x, int y) const { return pixels_[index(x, y)].count; }

  std::uint64_t bad_sample_count() const { return bad_count_; }
  // FilmSample::rays summed over every sample added (the render's ray count,
  // taken in the film's pass over the samples rather than in one more).
  std::uint64_t rays_cast() const { return rays_; }
  const std::vector<BadSample>& bad_samples() const { return bad_kept_; }
  static constexpr std::size_t kMaxBadSamplesKept = 16;

  // The film's whole state as arrays of 64-bit words, for the partial film
  // file (core/partial_film.h): per pixel, 7 words of first sums (three
  // Sum1 and the count), 6 of second moments (three Sum2; none for a
  // FilmMoments::Mean film), 10 of splat sums (two Sum1 and three Sum1; none
  // for the box filter).
  static constexpr std::size_t kPixelWords = 7, kMomentWords = 6, kSplatWords = 10;
  struct Words {
    std::span<std::uint64_t> pixels, moments, splat;
  };
  struct ConstWords {
    std::span<const std::uint64_t> pixels, moments, splat;
  };
  Words words();
  ConstWords words() const;
  // Adds arrays laid out as words() (what add() does, for code that moves
  // films as words: the MPI reduction). `pixels` elements of kPixelWords
  // words; `sums` 128-bit sums of two words (the moments and splat arrays).
  static void add_pixel_words(const std::uint64_t* in, std::uint64_t* inout, std::size_t pixels);
  static void add_sum_words(const std::uint64_t* in, std::uint64_t* inout, std::size_t sums);
  // The counts a state restored into words() goes with.
  void restore_counts(std::uint64_t bad, std::uint64_t rays, std::vector<BadSample> kept);

 private:
  // What every film keeps per pixel: sum(w L) and the count of its own
  // samples. With the box filter every weight is 1, so sum(w) and sum(w^2)
  // are the count and sum(w^2 L) is sum(w L).
  // (No member initialisers: the film zeroes its arrays in parallel.)
  struct Pixel {
    Sum1 sum_wL[3];
    std::uint64_t count;
  };
  struct Moments {
    Sum2 sum_w2L2[3];  // sum(w^2 L^2)
  };
  // What a splatting filter (w != 1) adds: sum(w), and for the variance
  // sum(w^2) and sum(w^2 L).
  struct SplatSums {
    Sum1 sum_w;
    Sum1 sum_w2;
    Sum1 sum_w2L[3];
  };
  // A pixel's sums whatever the filter.
  struct Sums {
    double sum_w, sum_w2;
    dvec3 sum_wL, sum_w2L, sum_w2L2;
  };
  Sums sums(int x, int y) const;
  void require_variance() const;
  std::size_t index(int x, int y) const { return static_cast<std::size_t>(y) * width_ + x; }
  // Records the batch's bad samples, keeping the first kMaxBadSamplesKept
  // in the canonical order (the rare path).
  void record_bad(std::uint32_t first, std::uint32_t count, std::span<const FilmSample> samples);
  void keep_bad(std::vector<BadSample> more);

  int width_, height_;
  FilterKind filter_;
  FilmMoments moments_;
  HugePageVector<Pixel> pixels_;
  HugePageVector<Moments> moments_sums_;  // empty for FilmMoments::Mean
  HugePageVector<SplatSums> splat_;  // empty for the box filter
  std::uint64_t bad_count_ = 0;
  std::uint64_t rays_ = 0;
  std::vector<BadSample> bad_kept_;
};

}  // namespace pathlab
