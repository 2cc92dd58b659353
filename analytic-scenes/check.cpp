#include "analytic-scenes/check.h"

#include <algorithm>
#include <cmath>

namespace pathlab {

double normal_two_sided_quantile(double p) {
  // Bisection on the monotone tail erfc(z / sqrt 2): exact to double
  // rounding for any p, no table needed.
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return hi;
}

void write_check_images(const std::filesystem::path& dir, const Film& film, const ExpectedImage& expected,
                        const CheckResult& result, const ImageMetadata& metadata) {
  write_exr(dir / "rendered.exr", film.image(), metadata);
  write_exr(dir / "expected.exr", expected.mean, metadata);
  write_exr(dir / "error.exr", result.error, metadata);
  write_exr(dir / "zscore.exr", result.z, metadata);
}

CheckResult check_against_expected(const Film& film, const ExpectedImage& expected, const CheckOptions& options,
                                   std::size_t keep_worst) {
  const int w = film.width(), h = film.height();
  const double n = 3.0 * w * h;
  CheckResult r;
  r.error = Image(w, h);
  r.z = Image(w, h);
  r.z_threshold = normal_two_sided_quantile(-std::expm1(std::log1p(-options.alpha) / n));
  r.bias_threshold = normal_two_sided_quantile(-std::expm1(std::log1p(-options.alpha) / 3.0));
  dvec3 sum_d(0.0), sum_var(0.0);
  double sum_d2 = 0.0, sum_rel = 0.0;
  std::vector<PixelDeviation> all;
  all.reserve(static_cast<std::size_t>(n));
  const Image film_var = film.variance_of_mean();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Spectrum m = film.mean(x, y);
      for (int c = 0; c < 3; ++c) {
        const double e = expected.mean.at(x, y)[c], q = expected.quadrature_error.at(x, y)[c];
        const double d = double(m[c]) - e;
        const double floor = options.rel_floor * std::abs(e) + options.abs_floor;
        const double n_own = std::max<double>(1.0, static_cast<double>(film.sample_count(x, y)));
        double var_3x3 = 0.0;
        for (int ny = std::max(0, y - 1); ny <= std::min(h - 1, y + 1); ++ny)
          for (int nx = std::max(0, x - 1); nx <= std::min(w - 1, x + 1); ++nx)
            var_3x3 = std::max(var_3x3, double(film_var.at(nx, ny)[c]));
        const double var = std::max(var_3x3, double(expected.footprint_variance.at(x, y)[c]) / n_own);
        const double sigma = std::sqrt(var + q * q + floor * floor);
        const double z = d / sigma;
        r.error.at(x, y)[c] = static_cast<float>(d);
        r.z.at(x, y)[c] = static_cast<float>(z);
        all.push_back({x, y, c, z, double(m[c]), e, sigma});
        sum_d[c] += d;
        sum_d2 += d * d;
        sum_rel += d * d / ((e + 0.01) * (e + 0.01));
        sum_var[c] += var + q * q + floor * floor;
        if (std::abs(z) > r.z_threshold) ++r.failing;
      }
    }
  const double pixels = static_cast<double>(w) * h;
  const double inflate = film.filter() == FilterKind::Bilinear ? 3.0 : 1.0;
  for (int c = 0; c < 3; ++c) {
    const double bias = sum_d[c] / pixels, se = std::sqrt(sum_var[c]) / pixels * inflate;
    if (c == 0 || std::abs(bias / se) > std::abs(r.bias_z)) {
      r.bias_channel = c;
      r.bias = bias;
      r.bias_se = se;
      r.bias_z = bias / se;
    }
  }
  r.rmse = std::sqrt(sum_d2 / n);
  r.rel_mse = sum_rel / n;
  r.pixels_pass = r.failing == 0;
  r.bias_pass = std::abs(r.bias_z) <= r.bias_threshold;
  r.pass = r.pixels_pass && r.bias_pass;
  const std::size_t k = std::min(keep_worst, all.size());
  std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k), all.end(),
                    [](const PixelDeviation& a, const PixelDeviation& b) { return std::abs(a.z) > std::abs(b.z); });
  r.worst.assign(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k));
  return r;
}

}  // namespace pathlab
