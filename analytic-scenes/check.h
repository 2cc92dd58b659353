// Deciding, with statistics, whether a render matches its expected image.
//
// Per pixel and channel: z = (rendered - expected) / s, where
//   s^2 = max(Var_3x3(rendered), footprint_variance / n) + quadrature_error^2 + floor^2,
// Var_3x3(rendered) the largest of the film's estimates of the variance of
// the pixel mean over the pixel and its 8 neighbours, n the
// pixel's sample count, footprint_variance / n a lower bound on the true
// variance (expected_image.h), and
// floor = rel_floor * |expected| + abs_floor, so that a pixel whose samples
// all agree (zero sample variance) is judged by float rounding, not divided
// by zero. The threshold on max |z| comes from a Šidák correction: the
// family of N = pixels x 3 tests has false-alarm rate alpha.
//
// Why the neighbourhood: a path tracer's per-sample distribution is often
// very skewed (Russian roulette, a light found rarely), and with tens of
// samples a pixel can see only its common outcome: zero sample variance,
// a mean off by the missing rare part, and a huge z. Neighbouring pixels
// share the estimator's distribution, so the largest variance among them is
// a sound stand-in; it costs some power next to a variance boundary (an
// umbra pixel beside a lit one), never false alarms.
//
// Globally, per channel (the channels of one path are correlated, so they
// are three tests, Šidák-corrected): the mean of (rendered - expected) over
// all pixels, with its standard error. With the bilinear filter neighbouring pixels share samples; each
// sample reaches at most 4 pixels, so the standard error of the mean is
// inflated by 3 (covariances with the 8 neighbours bounded by the variances).
#pragma once

#include "analytic-scenes/expected_image.h"
#include "core/film.h"

#include <filesystem>
#include <vector>

namespace pathlab {

struct CheckOptions {
  double alpha = 1e-4;      // family-wise false-alarm rate
  double rel_floor = 1e-5;  // relative standard-deviation floor
  double abs_floor = 1e-7;
};

struct PixelDeviation {
  int x = 0, y = 0, channel = 0;
  double z = 0.0, rendered = 0.0, expected = 0.0, sigma = 0.0;
};

struct CheckResult {
  bool pass = false;
  bool pixels_pass = false, bias_pass = false;
  double z_threshold = 0.0;       // per pixel-channel, Šidák-corrected
  // The channel whose mean deviation is the most significant.
  int bias_channel = 0;
  double bias = 0.0, bias_se = 0.0, bias_z = 0.0, bias_threshold = 0.0;
  double rmse = 0.0, rel_mse = 0.0;  // rel_mse: (rendered - expected)^2 / (expected + 0.01)^2
  std::size_t failing = 0;        // pixel-channels beyond z_threshold
  std::vector<PixelDeviation> worst;  // largest |z| first
  Image error;                    // rendered - expected
  Image z;                        // per-channel z-scores
};

CheckResult check_against_expected(const Film& film, const ExpectedImage& expected, const CheckOptions& options = {},
                                   std::size_t keep_worst = 5);

// Writes rendered.exr, expected.exr, error.exr (rendered - expected) and
// zscore.exr into `dir` (created if needed). Throws InputError if it cannot.
void write_check_images(const std::filesystem::path& dir, const Film& film, const ExpectedImage& expected,
                        const CheckResult& result, const ImageMetadata& metadata);

// |z| beyond which a two-sided test of a standard normal has tail
// probability p.
double normal_two_sided_quantile(double p);

}  // namespace pathlab
