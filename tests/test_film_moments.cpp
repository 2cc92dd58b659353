// The film's first and second moments against closed forms on constructed
// samples (label "unit"), for both filters: the mean sum(w L) / sum(w) and
// the delta-method variance of that ratio (film.h),
//   Var(I) = n_eff / (n_eff - 1) * sum(w^2 (L - I)^2) / (sum w)^2,
//   n_eff  = (sum w)^2 / sum(w^2),
// which for the box filter (w = 1) is the unbiased sample variance over n.
// The expected values are computed here from the list of samples, term by
// term (sum of w^2 (L - I)^2 directly, not the film's expanded form), and the
// tent weights of the bilinear filter from their definition
// w = (1 - |dx|)(1 - |dy|) with dx, dy the sample's offset from the pixel
// centre, 0 beyond one pixel.
#include "core/film.h"

#include <gtest/gtest.h>

#include <vector>

namespace pathlab {
namespace {

struct Expected {
  dvec3 mean{0.0}, variance{0.0};
};

struct Weighted {
  double w;
  dvec3 L;
};

Expected closed_form(const std::vector<Weighted>& s) {
  double sw = 0.0, sw2 = 0.0;
  dvec3 swl(0.0);
  for (const Weighted& x : s) {
    sw += x.w;
    sw2 += x.w * x.w;
    swl += x.w * x.L;
  }
  Expected e;
  if (sw <= 0.0) return e;
  e.mean = swl / sw;
  dvec3 ss(0.0);
  for (const Weighted& x : s) ss += x.w * x.w * (x.L - e.mean) * (x.L - e.mean);
  const double n_eff = sw * sw / sw2;
  e.variance = n_eff > 1.0 ? ss * (n_eff / (n_eff - 1.0)) / (sw * sw) : dvec3(0.0);
  return e;
}

void expect_pixel(const Film& film, int x, int y, const Expected& e, const char* what) {
  const Spectrum m = film.mean(x, y), v = film.variance_of_mean(x, y);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(m[c], e.mean[c], 1e-6 * std::max(1.0, std::abs(e.mean[c]))) << what << " mean, channel " << c;
    EXPECT_NEAR(v[c], e.variance[c], 1e-6 * std::max(1e-3, std::abs(e.variance[c])))
        << what << " variance, channel " << c;
  }
}

// Box: four samples of known values in one pixel, one in another, none in a
// third. Pixel (0,0): L = 1, 2, 3, 6 (red), mean 3, sample variance
// (4 + 1 + 0 + 9) / 3 = 14/3, variance of the mean 14/12; the other
// channels scaled and shifted.
TEST(FilmMoments, BoxMeanAndVarianceOfTheMeanByHand) {
  Film film(3, 1, FilterKind::Box);
  const std::uint32_t count = 4;
  std::vector<FilmSample> s(3 * count);
  const double red[4] = {1, 2, 3, 6};
  for (std::uint32_t j = 0; j < count; ++j) {
    s[j].film = vec2(0.5f, 0.5f);
    s[j].L = Spectrum(float(red[j]), float(10.0 * red[j]), float(red[j] - 100.0));
    s[count + j].film = vec2(1.5f, 0.5f);
    s[count + j].L = Spectrum(j == 0 ? 7.0f : std::nanf(""));  // one good sample, three bad
    s[2 * count + j].film = vec2(2.5f, 0.5f);
    s[2 * count + j].L = Spectrum(std::numeric_limits<float>::infinity());  // none good
  }
  film.add_batch(0, count, s);
  const Spectrum m = film.mean(0, 0), v = film.variance_of_mean(0, 0);
  EXPECT_NEAR(m.x, 3.0, 1e-7);
  EXPECT_NEAR(v.x, 14.0 / 12.0, 1e-7);
  EXPECT_NEAR(v.y, 100.0 * 14.0 / 12.0, 1e-5);  // scaling by 10: variance x 100
  EXPECT_NEAR(v.z, 14.0 / 12.0, 1e-6);          // a shift leaves it alone
  std::vector<Weighted> w;
  for (std::uint32_t j = 0; j < count; ++j) w.push_back({1.0, dvec3(s[j].L)});
  expect_pixel(film, 0, 0, closed_form(w), "box pixel (0,0)");
  // One sample: its value, and no variance estimate (n - 1 = 0).
  EXPECT_EQ(film.sample_count(1, 0), 1u);
  EXPECT_NEAR(film.mean(1, 0).x, 7.0, 1e-7);
  EXPECT_EQ(film.variance_of_mean(1, 0), Spectrum(0.0f));
  EXPECT_EQ(film.mean(2, 0), Spectrum(0.0f));
  EXPECT_EQ(film.variance_of_mean(2, 0), Spectrum(0.0f));
  EXPECT_EQ(film.bad_sample_count(), 3u + 4u);
  // A second batch adds to the same moments: 8 samples, mean 3, variance
  // of the mean (2 * 14) / 7 / 8.
  Film film2(3, 1, FilterKind::Box);
  film2.add_batch(0, count, s);
  film2.add_batch(count, count, s);
  EXPECT_NEAR(film2.variance_of_mean(0, 0).x, 28.0 / 7.0 / 8.0, 1e-7);
}

// Bilinear: a 3x3 film, two samples per pixel at chosen offsets; every
// pixel's mean and variance against the closed form over the tent weights
// of the samples within one pixel of its centre.
TEST(FilmMoments, BilinearWeightedMeanAndDeltaMethodVariance) {
  const int W = 3, H = 3;
  const std::uint32_t count = 2;
  Film film(W, H, FilterKind::Bilinear);
  std::vector<FilmSample> s(W * H * count);
  const vec2 offsets[2] = {vec2(0.2f, 0.7f), vec2(0.85f, 0.4f)};
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (std::uint32_t j = 0; j < count; ++j) {
        FilmSample& f = s[(y * W + x) * count + j];
        f.film = vec2(float(x), float(y)) + offsets[j];
        const float v = float(1 + x + 3 * y) * (j == 0 ? 1.0f : 2.5f);
        f.L = Spectrum(v, v * v * 0.1f, 5.0f - v);
      }
  film.add_batch(0, count, s);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      std::vector<Weighted> list;
      const double cx = x + 0.5, cy = y + 0.5;
      for (const FilmSample& f : s) {
        const double wx = 1.0 - std::abs(double(f.film.x) - cx), wy = 1.0 - std::abs(double(f.film.y) - cy);
        if (wx > 0.0 && wy > 0.0) list.push_back({wx * wy, dvec3(f.L)});
      }
      ASSERT_GE(list.size(), 3u);
      const std::string where = "bilinear pixel " + std::to_string(x) + "," + std::to_string(y);
      expect_pixel(film, x, y, closed_form(list), where.c_str());
    }
  // By hand, the centre pixel's weights: sample (1,1,j=0) at offset (0.2, 0.7)
  // is 0.3 and 0.2 from the centre: w = 0.7 * 0.8 = 0.56.
  Film one(3, 3, FilterKind::Bilinear);
  std::vector<FilmSample> single(9);
  for (int i = 0; i < 9; ++i) single[i].film = vec2(float(i % 3) + 0.5f, float(i / 3) + 0.5f);
  single[4].film = vec2(1.2f, 1.7f);
  single[4].L = Spectrum(2.0f);
  single[1].film = vec2(1.5f, 0.9f);  // 0.6 above the centre: w = 0.4
  single[1].L = Spectrum(5.0f);
  one.add_batch(0, 1, single);
  // I = (0.56 * 2 + 0.4 * 5) / 0.96 = 3.25; n_eff = 0.96^2 / (0.56^2 + 0.4^2);
  // sum w^2 (L - I)^2 = 0.3136 * 1.5625 + 0.16 * 3.0625 = 0.98
  const double sw = 0.96, sw2 = 0.56 * 0.56 + 0.16, ss = 0.3136 * 1.5625 + 0.16 * 3.0625;
  const double n_eff = sw * sw / sw2;
  EXPECT_NEAR(one.mean(1, 1).x, 3.25, 1e-6);
  EXPECT_NEAR(one.variance_of_mean(1, 1).x, ss * n_eff / (n_eff - 1.0) / (sw * sw), 1e-6);
}

// Films of split samples add up to the film of all (Film::add), and the
// moments survive it: the variance after add() is the closed form of the
// union.
TEST(FilmMoments, AddedFilmsHaveTheMomentsOfTheUnion) {
  for (const FilterKind filter : {FilterKind::Box, FilterKind::Bilinear}) {
    Film a(2, 2, filter), b(2, 2, filter), all(2, 2, filter);
    std::vector<FilmSample> s1(4), s2(4);
    for (int i = 0; i < 4; ++i) {
      s1[i].film = vec2(float(i % 2) + 0.3f, float(i / 2) + 0.6f);
      s1[i].L = Spectrum(float(i + 1));
      s2[i].film = vec2(float(i % 2) + 0.7f, float(i / 2) + 0.45f);
      s2[i].L = Spectrum(float(3 * i) + 0.5f);
    }
    a.add_batch(0, 1, s1);
    b.add_batch(1, 1, s2);
    std::vector<FilmSample> both(8);
    for (int i = 0; i < 4; ++i) {
      both[2 * i] = s1[i];
      both[2 * i + 1] = s2[i];
    }
    all.add_batch(0, 2, both);
    a.add(b);
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) {
        EXPECT_EQ(a.mean(x, y), all.mean(x, y));
        EXPECT_EQ(a.variance_of_mean(x, y), all.variance_of_mean(x, y));
      }
    if (filter == FilterKind::Box) {
      // Pixel (0,0): samples 1 and 0.5: mean 0.75, variance of the mean
      // ((0.25)^2 * 2 / 1) / 2 = 0.0625.
      EXPECT_NEAR(a.mean(0, 0).x, 0.75, 1e-7);
      EXPECT_NEAR(a.variance_of_mean(0, 0).x, 0.0625, 1e-7);
    }
  }
}

// The fixed-point sums (fixed_sum.h): a term is rounded to the nearest unit
// 2^-F, so a sum of k copies of x is k round(x) units exactly, and Sum2's
// units are 2^-32: 0.1^2 summed 1000 times is 10 to 1000 * 2^-33.
TEST(FilmMoments, FixedPointSumsAreExactMultiplesOfTheRoundedTerm) {
  Sum1 s1;
  Sum2 s2;
  for (int i = 0; i < 1000; ++i) {
    s1.add(0.1);
    s2.add(0.01);
  }
  EXPECT_NEAR(s1.value(), 100.0, 1000 * 0x1p-65);
  EXPECT_NEAR(s2.value(), 10.0, 1000 * 0x1p-33);
  EXPECT_EQ(s2.value(), std::ldexp(1000.0 * std::round(0.01 * 0x1p32), -32));
  Sum2 neg;
  neg.add(-2.5);
  neg.add(2.5);
  EXPECT_EQ(neg.value(), 0.0);
}

}  // namespace
}  // namespace pathlab
