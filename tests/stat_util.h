// Statistics for tests: chi-square and normal critical values, the Šidák
// correction, Poisson tails and Pearson chi-square statistics. One copy,
// shared by test_rng.cpp, test_sampling.cpp, test_camera.cpp and
// test_strategies.cpp.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace pathlab::test {

// Regularized upper incomplete gamma Q(a, x) (series for P if x < a + 1, else Lentz's continued fraction; NR3 6.2).
inline double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double log_prefactor = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double ap = a, term = 1.0 / a, sum = term;
    for (int n = 0; n < 10000 && std::abs(term) > std::abs(sum) * 1e-16; ++n) {
      ap += 1.0;
      term *= x / ap;
      sum += term;
    }
    return 1.0 - sum * std::exp(log_prefactor);
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return std::exp(log_prefactor) * h;
}

// P(X > x) for X ~ chi-square with `dof` degrees of freedom.
inline double chi2_sf(double x, double dof) { return gamma_q(0.5 * dof, 0.5 * x); }

// The upper critical value c with P(X > c) = alpha for X ~ chi2(dof), by bisection.
inline double chi2_critical(double dof, double alpha) {
  double lo = 0.0, hi = dof + 10.0;
  while (chi2_sf(hi, dof) > alpha) hi *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chi2_sf(mid, dof) > alpha ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Two-sided tail probability P(|Z| > |z|) of a standard normal Z.
inline double normal_two_sided_p(double z) { return std::erfc(std::abs(z) / std::sqrt(2.0)); }

// Final bisection bracket (lo, hi), 200 halvings of [0, 40], of the z with P(|Z| > z) = alpha.
inline std::pair<double, double> z_critical_bracket(double alpha) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (normal_two_sided_p(mid) > alpha ? lo : hi) = mid;
  }
  return {lo, hi};
}

// Two-sided standard normal critical value z with P(|Z| > z) = alpha (midpoint of the bracket).
inline double z_critical(double alpha) {
  const auto [lo, hi] = z_critical_bracket(alpha);
  return 0.5 * (lo + hi);
}

// Šidák per-comparison level 1 - (1 - alpha)^(1/m) keeping the family-wise level at alpha over m comparisons.
inline double sidak(double alpha, double m) { return -std::expm1(std::log1p(-alpha) / m); }

// The |z| beyond which m two-sided tests have family-wise false-alarm rate alpha (upper end of the bracket).
inline double sidak_z(double alpha, double m) { return z_critical_bracket(sidak(alpha, m)).second; }

// P(X >= k) for X ~ Poisson(lambda).
inline double poisson_sf(long k, double lambda) {
  double pmf = std::exp(-lambda), below = 0.0;
  for (long i = 0; i < k; ++i) {
    below += pmf;
    pmf *= lambda / static_cast<double>(i + 1);
  }
  return std::max(0.0, 1.0 - below);
}

// Pearson chi-square statistic of `counts` against equal expected counts n / counts.size().
template <typename Count>
inline double chi2_equal(const std::vector<Count>& counts, double n) {
  const double expected = n / static_cast<double>(counts.size());
  double stat = 0.0;
  for (const Count c : counts) stat += (c - expected) * (c - expected) / expected;
  return stat;
}

// Pearson chi-square goodness-of-fit test at level alpha, bins pooled in increasing expected count to >= 5 each.
inline testing::AssertionResult chi2_fit(const std::vector<double>& observed, const std::vector<double>& expected,
                                         double alpha) {
  std::vector<std::size_t> order(observed.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return expected[a] < expected[b]; });
  // A remainder below 5 joins the last pooled bin; a sample in a bin of zero expected count fails outright.
  std::vector<std::pair<double, double>> pooled;  // (observed, expected)
  double pool_obs = 0.0, pool_exp = 0.0;
  for (const std::size_t i : order) {
    if (expected[i] <= 0.0) {
      if (observed[i] > 0.0)
        return testing::AssertionFailure() << observed[i] << " samples in bin " << i << " of zero density";
      continue;
    }
    pool_obs += observed[i];
    pool_exp += expected[i];
    if (pool_exp >= 5.0) {
      pooled.emplace_back(pool_obs, pool_exp);
      pool_obs = pool_exp = 0.0;
    }
  }
  if (pool_exp > 0.0) {
    if (pooled.empty()) return testing::AssertionFailure() << "fewer than 5 expected samples in all";
    pooled.back().first += pool_obs;
    pooled.back().second += pool_exp;
  }
  double stat = 0.0;
  for (const auto& [o, e] : pooled) stat += (o - e) * (o - e) / e;
  const double dof = static_cast<double>(pooled.size()) - 1.0;
  const double crit = chi2_critical(dof, alpha);
  if (stat > crit)
    return testing::AssertionFailure() << "chi2(" << dof << ") = " << stat << " > " << crit << " ("
                                       << observed.size() << " bins pooled into " << pooled.size() << ")";
  return testing::AssertionSuccess();
}

}  // namespace pathlab::test
