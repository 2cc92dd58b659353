// Checks of an environment map's importance sampler against its own pdf()
// (core/environment_map.h), shared by the unit tests (synthetic maps) and
// the data tests (the fetched maps).
//
// Bins are a grid over the map's (u, v) in the test's own lat-long
// convention (written out here, pinned by EnvironmentMap.Orientation). The
// expected count of a bin integrates pdf(direction) * 2 pi^2 sin(theta) over
// it on a grid of cells that nest both inside the bins and inside the
// texels: the density in (u, v) is constant on each such cell, so the
// midpoint rule is exact up to rounding, however bright or small a texel.
#pragma once

#include "core/environment_map.h"
#include "core/math.h"
#include "tests/stat_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

namespace pathlab::test {

// The convention of docs/scene-format.md: (u, v) of a unit direction in the
// map's frame, and back.
inline glm::dvec2 latlong_uv(const dvec3& d) {
  double u = std::atan2(d.x, -d.z) / (2.0 * M_PI);
  if (u < 0.0) u += 1.0;
  return glm::dvec2(u >= 1.0 ? 0.0 : u, std::acos(std::clamp(d.y, -1.0, 1.0)) / M_PI);
}
inline dvec3 latlong_direction(const glm::dvec2& uv) {
  const double theta = M_PI * uv.y, phi = 2.0 * M_PI * uv.x;
  return dvec3(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
}

// Integral of map.pdf over bin (bx, by) of a bins_u x bins_v grid, by cells
// `cells_u` x `cells_v` over the whole map (multiples of both the bins and
// the texels), for every bin at once.
inline std::vector<double> pdf_per_bin(const EnvironmentMap& map, int bins_u, int bins_v, int cells_u, int cells_v) {
  std::vector<double> mass(static_cast<std::size_t>(bins_u) * bins_v, 0.0);
  const double du = 1.0 / cells_u, dv = 1.0 / cells_v;
  for (int j = 0; j < cells_v; ++j) {
    const double v = (j + 0.5) * dv;
    const double jacobian = 2.0 * M_PI * M_PI * std::sin(M_PI * v);
    const int by = j * bins_v / cells_v;
    for (int i = 0; i < cells_u; ++i) {
      const dvec3 local = latlong_direction(glm::dvec2((i + 0.5) * du, v));
      const vec3 world = map.to_world() * vec3(local);
      mass[static_cast<std::size_t>(by) * bins_u + i * bins_u / cells_u] += map.pdf(world) * jacobian * du * dv;
    }
  }
  return mass;
}

// The least common multiple of a and b (the cell grid of pdf_per_bin).
inline int lcm_of(int a, int b) { return a / std::gcd(a, b) * b; }

// `n` directions from map.sample() with a fixed seed, binned as above, against
// the integrated pdf: Pearson chi-square at level alpha (bins pooled to >= 5
// expected). Also every sample's pdf matches pdf() of its direction, and no
// direction has density 0.
inline testing::AssertionResult sampler_matches_pdf(const EnvironmentMap& map, int bins_u, int bins_v, std::size_t n,
                                                    double alpha, std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<double> observed(static_cast<std::size_t>(bins_u) * bins_v, 0.0);
  const mat3 to_local = glm::transpose(map.to_world());
  std::size_t failed = 0, mismatched = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const vec2 u(uniform(rng), uniform(rng));
    const std::optional<EnvironmentMap::Sample> s = map.sample(u);
    if (!s) {
      ++failed;
      continue;
    }
    if (!(s->pdf > 0.0f)) return testing::AssertionFailure() << "sample " << k << " has pdf " << s->pdf;
    // The drawn texel's density and radiance: those of pdf() and radiance()
    // at wi, but where rounding put wi across the texel's edge.
    if (std::abs(s->pdf - map.pdf(s->wi)) > 1e-4f * s->pdf || s->radiance != map.radiance(s->wi)) ++mismatched;
    const glm::dvec2 uv = latlong_uv(dvec3(to_local * s->wi));
    const int bx = std::min(bins_u - 1, static_cast<int>(uv.x * bins_u));
    const int by = std::min(bins_v - 1, static_cast<int>(uv.y * bins_v));
    observed[static_cast<std::size_t>(by) * bins_u + bx] += 1.0;
  }
  // A draw may fail only on a pole: probability 0 for a continuous u.
  if (failed > 0) return testing::AssertionFailure() << failed << " of " << n << " draws returned nothing";
  // Within float rounding of a texel edge: a few in 10^5 at most.
  if (mismatched > n / 10000)
    return testing::AssertionFailure() << mismatched << " of " << n << " samples disagree with pdf() or radiance()";
  const std::vector<double> mass =
      pdf_per_bin(map, bins_u, bins_v, lcm_of(bins_u, map.width()), lcm_of(bins_v, map.height()));
  const double total = std::accumulate(mass.begin(), mass.end(), 0.0);
  if (std::abs(total - 1.0) > 1e-4) return testing::AssertionFailure() << "pdf integrates to " << total;
  std::vector<double> expected(mass.size());
  for (std::size_t i = 0; i < mass.size(); ++i) expected[i] = mass[i] * static_cast<double>(n);
  return chi2_fit(observed, expected, alpha);
}

}  // namespace pathlab::test
