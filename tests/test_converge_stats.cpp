// The statistics `pathlab converge` reports, against known answers: the
// one-film standard error of the bias on synthetic films whose true
// standard error is known in closed form (or measured over many replicate
// films), the seeds' spread and Student's t, and when two configurations'
// curves are indistinguishable. Label unit: synthetic inputs, no render.
#include "core/film.h"
#include "debugtools/converge.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace pathlab {
namespace {

// A film of w x h pixels, n samples each, every sample's radiance from
// `draw`, placed uniformly in its pixel.
template <typename Draw>
Film synthetic_film(int w, int h, FilterKind filter, std::uint32_t n, std::mt19937_64& rng, Draw draw) {
  Film film(w, h, filter);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<FilmSample> samples(static_cast<std::size_t>(w) * h * n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (std::uint32_t j = 0; j < n; ++j) {
        FilmSample& s = samples[(static_cast<std::size_t>(y) * w + x) * n + j];
        s.film = vec2(static_cast<float>(x) + u(rng), static_cast<float>(y) + u(rng));
        s.L = draw(rng);
      }
  film.add_batch(0, n, samples);
  return film;
}

Image constant_image(int w, int h, float v) {
  Image i(w, h);
  for (vec3& p : i.pixels) p = vec3(v);
  return i;
}

// u ~ U(0, 1): variance 1/12, kurtosis 9/5, so the sample variance of N
// draws has relative standard deviation sqrt((9/5 - 1) / N) and its square
// root half that.
double uniform_sd_rel_error(double draws) { return 0.5 * std::sqrt(0.8 / draws); }

// A white pixel: the three channels of a sample are the same draw. The
// bias (mean over pixels and channels) then has standard error
// sqrt(1/12 / (n P)) exactly; channels taken as independent gave that over
// sqrt(3).
TEST(ConvergeBiasSe, BoxFilmWithEqualChannelsMatchesTheClosedForm) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int w = 16, h = 16;
  const std::uint32_t n = 64;
  const Film film = synthetic_film(w, h, FilterKind::Box, n, rng, [&](auto& r) { return Spectrum(u(r)); });
  const double truth = std::sqrt(1.0 / 12.0 / (double(n) * w * h));
  const double se = one_film_bias_se(film, constant_image(w, h, 0.5f));
  EXPECT_NEAR(se / truth, 1.0, 5.0 * uniform_sd_rel_error(double(n) * w * h)) << se << " vs " << truth;
}

// Independent channels: the true standard error is sqrt(1/12 / (3 n P));
// the bound (sum of the channels' sds) is sqrt(3) times it, never below.
TEST(ConvergeBiasSe, BoxFilmWithIndependentChannelsIsBoundedFromAbove) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int w = 16, h = 16;
  const std::uint32_t n = 64;
  const Film film = synthetic_film(w, h, FilterKind::Box, n, rng, [&](auto& r) { return Spectrum(u(r), u(r), u(r)); });
  const double truth = std::sqrt(1.0 / 12.0 / (3.0 * n * w * h));
  const double se = one_film_bias_se(film, constant_image(w, h, 0.5f));
  const double tol = 5.0 * uniform_sd_rel_error(3.0 * n * w * h);
  EXPECT_NEAR(se / truth, std::sqrt(3.0), std::sqrt(3.0) * tol) << se << " vs " << truth;
}

// The bilinear filter shares each sample among up to 4 pixels; no closed
// form, so the true standard error is the spread of the bias over M
// independent replicate films (its relative standard deviation about
// 1 / sqrt(2 (M - 1))). The one-film value must not fall below it (by more
// than 4 of those), nor exceed the bound's worst case, 3 times it.
TEST(ConvergeBiasSe, BilinearFilmIsNotBelowTheReplicatesSpread) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int w = 8, h = 8, M = 400;
  const std::uint32_t n = 16;
  const Image truth = constant_image(w, h, 0.5f);
  std::vector<double> biases;
  double reported = 0.0;
  for (int m = 0; m < M; ++m) {
    const Film film = synthetic_film(w, h, FilterKind::Bilinear, n, rng, [&](auto& r) { return Spectrum(u(r)); });
    double sum = 0.0;
    for (const vec3& p : film.image().pixels) sum += (double(p.x) - 0.5) + (double(p.y) - 0.5) + (double(p.z) - 0.5);
    biases.push_back(sum / (3.0 * w * h));
    reported += one_film_bias_se(film, truth) / M;
  }
  const double actual = seed_spread(biases).sd, rel = 1.0 / std::sqrt(2.0 * (M - 1));
  EXPECT_GE(reported, actual * (1.0 - 4.0 * rel)) << "one-film " << reported << ", spread of " << M << " films " << actual;
  EXPECT_LE(reported, 3.0 * actual * (1.0 + 4.0 * rel)) << "one-film " << reported << ", spread " << actual;
}

TEST(ConvergeBiasSe, LeavesOutExcludedPixels) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const Film film = synthetic_film(4, 4, FilterKind::Box, 8, rng, [&](auto& r) { return Spectrum(u(r)); });
  Image truth = constant_image(4, 4, 0.5f);
  for (int x = 0; x < 4; ++x) truth.at(x, 0) = vec3(std::nanf(""));
  double sum_var = 0.0;
  for (int y = 1; y < 4; ++y)
    for (int x = 0; x < 4; ++x) sum_var += 9.0 * film.variance_of_mean(x, y).x;  // (3 sd)^2, equal channels
  EXPECT_NEAR(one_film_bias_se(film, truth), std::sqrt(sum_var) / 36.0, 1e-9);
}

TEST(ConvergeSeeds, StudentQuantilesMatchTables) {
  EXPECT_NEAR(student_two_sided_quantile(0.05, 1), 12.7062, 1e-3);
  EXPECT_NEAR(student_two_sided_quantile(0.05, 3), 3.1824, 1e-3);
  EXPECT_NEAR(student_two_sided_quantile(0.05, 7), 2.3646, 1e-3);
  EXPECT_NEAR(student_two_sided_quantile(0.001, 7), 5.4079, 1e-3);
  EXPECT_NEAR(student_two_sided_quantile(0.01, 30), 2.7500, 1e-3);
  EXPECT_NEAR(student_two_sided_quantile(0.05, 100000), 1.9600, 1e-3);
}

// R = 4 normal draws, M times: the sample variance is unbiased (its mean
// over M sets has standard deviation sigma^2 sqrt(2 / (R - 1) / M)) and the
// 95 % interval mean +- t(0.05, 3) se covers the true mean in 95 % of the
// sets (binomial standard deviation sqrt(0.95 0.05 / M)).
TEST(ConvergeSeeds, SpreadIsUnbiasedAndItsIntervalCovers) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(1.0, 2.0);
  const int R = 4, M = 4000;
  const double t = student_two_sided_quantile(0.05, R - 1);
  double mean_var = 0.0, covered = 0.0;
  for (int m = 0; m < M; ++m) {
    std::vector<double> v;
    for (int r = 0; r < R; ++r) v.push_back(normal(rng));
    const SeedSpread s = seed_spread(v);
    mean_var += s.sd * s.sd / M;
    covered += (std::abs(s.mean - 1.0) <= t * s.se) ? 1.0 / M : 0.0;
  }
  EXPECT_NEAR(mean_var, 4.0, 5.0 * 4.0 * std::sqrt(2.0 / (R - 1) / M));
  EXPECT_NEAR(covered, 0.95, 5.0 * std::sqrt(0.95 * 0.05 / M));
}

// Two configurations over the same spp rungs and seeds.
ConvergeResult pair(const std::vector<double>& rmse_a, const std::vector<double>& rmse_b,
                    const std::vector<double>& sec_a, const std::vector<double>& sec_b) {
  ConvergeResult r;
  r.seeds = static_cast<int>(rmse_a.size());
  r.configs = {{"reference", Strategy::Mis, 0.0f, 3, "reference mis"}, {"reference", Strategy::Mis, 1.0f, 3, "reference mis clamp 1"}};
  for (std::size_t c = 0; c < 2; ++c)
    for (double spp : {1.0, 4.0}) {
      ConvergeRow row;
      row.config = c;
      row.budget = row.spp = spp;
      for (std::size_t s = 0; s < rmse_a.size(); ++s) {
        row.rmse_per_seed.push_back((c == 0 ? rmse_a[s] : rmse_b[s]) / std::sqrt(spp));
        row.seconds_per_seed.push_back((c == 0 ? sec_a[s] : sec_b[s]) * spp);
      }
      row.rmse = seed_spread(row.rmse_per_seed).mean;
      row.seconds = seed_spread(row.seconds_per_seed).mean;
      r.rows.push_back(row);
    }
  return r;
}

TEST(ConvergeTies, SamePathsAndTimesWithinNoiseHaveNoWinner) {
  // The same per-seed errors (the clamp never engages), times differing by
  // timing noise: indistinguishable, and the report names no winner.
  const ConvergeResult r = pair({0.1, 0.12, 0.09, 0.11}, {0.1, 0.12, 0.09, 0.11}, {1.0, 1.1, 0.95, 1.05}, {0.97, 1.08, 1.0, 1.02});
  EXPECT_EQ(indistinguishable_from(r, 0), std::vector<std::size_t>{1});
  EXPECT_EQ(indistinguishable_from(r, 1), std::vector<std::size_t>{0});
  const std::string text = first_to_reach_text(r, 0.06);
  EXPECT_NE(text.find("no winner among **reference mis"), std::string::npos) << text;
}

TEST(ConvergeTies, ASignificantDifferenceInTimeOrErrorIsAWinner) {
  // The same paths, one twice as fast (its times tightly spread): a real
  // winner.
  const ConvergeResult faster = pair({0.1, 0.12, 0.09, 0.11}, {0.1, 0.12, 0.09, 0.11}, {1.0, 1.01, 0.99, 1.0}, {2.0, 2.02, 1.99, 2.01});
  EXPECT_TRUE(indistinguishable_from(faster, 0).empty());
  EXPECT_NE(first_to_reach_text(faster, 0.06).find("**reference mis**"), std::string::npos);
  // Errors consistently 30 % apart, equal times: distinguishable.
  const ConvergeResult better = pair({0.1, 0.12, 0.09, 0.11}, {0.13, 0.155, 0.118, 0.142}, {1, 1, 1, 1}, {1, 1, 1, 1});
  EXPECT_TRUE(indistinguishable_from(better, 0).empty());
}

TEST(ConvergeTies, OneSeedListsOnlyEqualErrors) {
  EXPECT_EQ(indistinguishable_from(pair({0.1}, {0.1}, {1.0}, {3.0}), 0), std::vector<std::size_t>{1});
  EXPECT_TRUE(indistinguishable_from(pair({0.1}, {0.1001}, {1.0}, {1.0}), 0).empty());
}

}  // namespace
}  // namespace pathlab
