// Statistics for tests: two-sided z thresholds with a Šidák correction.
#pragma once

#include <cmath>

namespace pathlab::test {

// Two-sided tail probability of a standard normal beyond |z|.
inline double normal_two_sided_p(double z) { return std::erfc(std::abs(z) / std::sqrt(2.0)); }

// The |z| beyond which a family of m two-sided tests has family-wise false
// alarm rate alpha (Šidák: per-test alpha' = 1 - (1 - alpha)^(1/m)).
inline double sidak_z(double alpha, double m) {
  const double per_test = -std::expm1(std::log1p(-alpha) / m);
  double lo = 0.0, hi = 40.0;  // bisection on the monotone tail probability
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (normal_two_sided_p(mid) > per_test ? lo : hi) = mid;
  }
  return hi;
}

}  // namespace pathlab::test
