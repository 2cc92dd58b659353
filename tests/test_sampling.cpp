// The warps of core/sampling.h: each density integrates to one, each warp's
// samples stay in its domain and follow its density (chi-square goodness of
// fit, and a finite-difference Jacobian), each inverse inverts its warp; and
// the MIS helpers power_heuristic and area_to_solid_angle.
//
// Statistical tests draw their unit-square points from a fixed-seed
// std::mt19937_64 (not from the renderer's RNG, which test_rng.cpp covers),
// so they are deterministic; thresholds are chi-square critical values at a
// family-wise false-alarm rate kAlpha. The WarpPlantedBugs suite runs the
// same checks on deliberately broken warps and expects them to fail: it shows
// each check has the power to catch the class of bug it is there for.
#include "core/sampling.h"
#include "tests/stat_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <utility>
#include <vector>

namespace pathlab {
namespace {

// --- statistics ----------------------------------------------------------------

using test::chi2_critical;
using test::chi2_fit;

// False-alarm rate of each statistical test (each makes one comparison).
constexpr double kAlpha = 1e-3;


// Fixed-seed uniform points of [0,1)^2 (24-bit floats, like the renderer's).
class UniformSquare {
 public:
  explicit UniformSquare(std::uint64_t seed) : rng_(seed) {}
  vec2 next() {
    const float x = unit();
    return vec2(x, unit());
  }

 private:
  float unit() { return static_cast<float>(rng_() >> 40) * 0x1p-24f; }
  std::mt19937_64 rng_;
};

// --- the warps under test, as values ----------------------------------------------

constexpr double kPiD = std::numbers::pi;

using DirWarp = vec3 (*)(vec2);
using DirPdf = float (*)(const vec3&);
using DirInverse = vec2 (*)(const vec3&);
using PlaneWarp = vec2 (*)(vec2);

float sphere_pdf(const vec3&) { return uniform_sphere_pdf(); }

vec3 from_z_phi(double z, double phi) {
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
}
double phi_of(const vec3& w) {
  const double phi = std::atan2(static_cast<double>(w.y), static_cast<double>(w.x));
  return phi < 0.0 ? phi + 2.0 * kPiD : phi;
}

// --- densities integrate to one -------------------------------------------------

// Integral of a solid-angle density over the whole sphere, by the midpoint
// rule on a regular grid in (cos theta, phi), where d(omega) = dz dphi. The
// densities here are polynomials of degree <= 1 in z, for which the rule is
// exact: what remains is float rounding of the density, ~1e-7 relative.
double integral_over_sphere(DirPdf pdf) {
  constexpr int kNz = 512, kNphi = 512;
  const double dz = 2.0 / kNz, dphi = 2.0 * kPiD / kNphi;
  double sum = 0.0;
  for (int i = 0; i < kNz; ++i)
    for (int j = 0; j < kNphi; ++j) sum += pdf(from_z_phi(-1.0 + (i + 0.5) * dz, (j + 0.5) * dphi));
  return sum * dz * dphi;
}

TEST(WarpDensity, UniformSphereIntegratesToOne) { EXPECT_NEAR(integral_over_sphere(sphere_pdf), 1.0, 1e-5); }

TEST(WarpDensity, CosineHemisphereIntegratesToOneOverTheSphere) {
  // Over the whole sphere: the density must vanish below the horizon.
  EXPECT_NEAR(integral_over_sphere(cosine_hemisphere_pdf), 1.0, 1e-5);
  EXPECT_EQ(cosine_hemisphere_pdf(vec3(0.0f, 0.6f, -0.8f)), 0.0f);
  EXPECT_EQ(cosine_hemisphere_pdf(vec3(1.0f, 0.0f, 0.0f)), 0.0f);
}

// --- samples stay in their domain ----------------------------------------------

// Random points plus every combination of the extreme coordinates
// {0, 2^-24, 1/2, 1 - 2^-24}.
std::vector<vec2> domain_probe_points() {
  std::vector<vec2> pts;
  const float edges[] = {0.0f, 0x1p-24f, 0.5f, 1.0f - 0x1p-24f};
  for (const float a : edges)
    for (const float b : edges) pts.emplace_back(a, b);
  UniformSquare rng(11);
  for (int i = 0; i < 100000; ++i) pts.push_back(rng.next());
  return pts;
}

// Unit vectors (to a few float ulps), with z >= 0 if `upper_hemisphere`.
testing::AssertionResult samples_unit_directions(DirWarp warp, bool upper_hemisphere) {
  for (const vec2 u : domain_probe_points()) {
    const vec3 w = warp(u);
    const double len = std::sqrt(double(w.x) * w.x + double(w.y) * w.y + double(w.z) * w.z);
    if (!(std::abs(len - 1.0) <= 1e-6) || (upper_hemisphere && !(w.z >= 0.0f)))
      return testing::AssertionFailure() << "u = (" << u.x << ", " << u.y << ") -> (" << w.x << ", " << w.y << ", "
                                         << w.z << "), length " << len;
  }
  return testing::AssertionSuccess();
}

// In the closed unit disk, allowing the few-ulp rounding of r * (cos, sin).
testing::AssertionResult samples_in_unit_disk(PlaneWarp warp) {
  for (const vec2 u : domain_probe_points()) {
    const vec2 p = warp(u);
    const double r2 = double(p.x) * p.x + double(p.y) * p.y;
    if (!(r2 <= 1.0 + 1e-6))
      return testing::AssertionFailure() << "u = (" << u.x << ", " << u.y << ") -> (" << p.x << ", " << p.y
                                         << "), |p|^2 = " << r2;
  }
  return testing::AssertionSuccess();
}

// Barycentrics (b1, b2) with b1, b2 >= 0 and b0 = 1 - b1 - b2 >= 0, exactly.
testing::AssertionResult samples_in_triangle(PlaneWarp warp) {
  for (const vec2 u : domain_probe_points()) {
    const vec2 b = warp(u);
    if (!(b.x >= 0.0f && b.y >= 0.0f && 1.0f - b.x - b.y >= 0.0f))
      return testing::AssertionFailure() << "u = (" << u.x << ", " << u.y << ") -> (" << b.x << ", " << b.y << ")";
  }
  return testing::AssertionSuccess();
}

TEST(WarpDomain, UniformSphereGivesUnitVectors) {
  EXPECT_TRUE(samples_unit_directions(square_to_uniform_sphere, false));
}
TEST(WarpDomain, CosineHemisphereGivesUpperUnitVectors) {
  EXPECT_TRUE(samples_unit_directions(square_to_cosine_hemisphere, true));
}
TEST(WarpDomain, ConcentricDiskStaysInUnitDisk) { EXPECT_TRUE(samples_in_unit_disk(square_to_concentric_disk)); }
TEST(WarpDomain, TriangleStaysInside) { EXPECT_TRUE(samples_in_triangle(square_to_uniform_triangle)); }

// --- samples follow their density: chi-square goodness of fit --------------------

constexpr int kSamples = 100000;

// Bins equal in solid angle: kNz bands of z = cos(theta) over [-1, 1] times
// kNphi sectors. Expected counts integrate the density under test over each
// bin (4x4 midpoint rule, exact for densities linear in z).
testing::AssertionResult directions_match_pdf(DirWarp warp, DirPdf pdf) {
  constexpr int kNz = 32, kNphi = 32, kSub = 4;
  std::vector<double> observed(kNz * kNphi, 0.0), expected(kNz * kNphi, 0.0);
  UniformSquare rng(7);
  for (int i = 0; i < kSamples; ++i) {
    const vec3 w = warp(rng.next());
    if (!is_finite(w)) return testing::AssertionFailure() << "non-finite sample";
    const int iz = std::clamp(static_cast<int>((w.z + 1.0) * 0.5 * kNz), 0, kNz - 1);
    const int ip = std::clamp(static_cast<int>(phi_of(w) / (2.0 * kPiD) * kNphi), 0, kNphi - 1);
    observed[iz * kNphi + ip] += 1.0;
  }
  const double dz = 2.0 / (kNz * kSub), dphi = 2.0 * kPiD / (kNphi * kSub);
  for (int iz = 0; iz < kNz; ++iz)
    for (int ip = 0; ip < kNphi; ++ip) {
      double sum = 0.0;
      for (int a = 0; a < kSub; ++a)
        for (int b = 0; b < kSub; ++b)
          sum += pdf(from_z_phi(-1.0 + (iz * kSub + a + 0.5) * dz, (ip * kSub + b + 0.5) * dphi));
      expected[iz * kNphi + ip] = sum * dz * dphi * kSamples;
    }
  return chi2_fit(observed, expected, kAlpha);
}

// Equal-area bins of the unit disk: 16 annuli r^2 in [k/16, (k+1)/16) times
// 32 sectors; uniform density, so each expects kSamples / 512.
testing::AssertionResult disk_is_uniform(PlaneWarp warp) {
  constexpr int kRings = 16, kSectors = 32;
  std::vector<double> observed(kRings * kSectors, 0.0);
  UniformSquare rng(8);
  for (int i = 0; i < kSamples; ++i) {
    const vec2 p = warp(rng.next());
    const double r2 = double(p.x) * p.x + double(p.y) * p.y;
    if (!(r2 <= 1.0 + 1e-6)) return testing::AssertionFailure() << "sample outside the disk";
    const int ir = std::min(static_cast<int>(r2 * kRings), kRings - 1);
    const int is = std::clamp(static_cast<int>(phi_of(vec3(p, 0.0f)) / (2.0 * kPiD) * kSectors), 0, kSectors - 1);
    observed[ir * kSectors + is] += 1.0;
  }
  return chi2_fit(observed, std::vector<double>(observed.size(), double(kSamples) / observed.size()), kAlpha);
}

// The reference triangle b1, b2 >= 0, b1 + b2 <= 1 cut into n^2 congruent
// sub-triangles (grid cells below the anti-diagonal, and the upper halves of
// the cells below it); uniform density, so each expects kSamples / n^2.
testing::AssertionResult triangle_is_uniform(PlaneWarp warp) {
  constexpr int kN = 16;
  std::vector<double> observed(kN * kN * 2, 0.0), expected(kN * kN * 2, 0.0);
  for (int i = 0; i < kN; ++i)
    for (int j = 0; i + j < kN; ++j) {
      expected[(i * kN + j) * 2] = double(kSamples) / (kN * kN);                             // lower half
      if (i + j < kN - 1) expected[(i * kN + j) * 2 + 1] = double(kSamples) / (kN * kN);  // upper half
    }
  UniformSquare rng(9);
  for (int s = 0; s < kSamples; ++s) {
    const vec2 b = warp(rng.next());
    if (!(b.x >= 0.0f && b.y >= 0.0f && b.x + b.y <= 1.0f))
      return testing::AssertionFailure() << "sample (" << b.x << ", " << b.y << ") outside the triangle";
    const double x = b.x * kN, y = b.y * kN;
    const int i = std::min(static_cast<int>(x), kN - 1), j = std::min(static_cast<int>(y), kN - 1 - i);
    // Cells on the anti-diagonal have no upper half (guards rounding of x + y).
    const int upper = i + j < kN - 1 && (x - i) + (y - j) > 1.0 ? 1 : 0;
    observed[(i * kN + j) * 2 + upper] += 1.0;
  }
  return chi2_fit(observed, expected, kAlpha);
}

TEST(WarpDistribution, UniformSphereMatchesItsPdf) {
  EXPECT_TRUE(directions_match_pdf(square_to_uniform_sphere, sphere_pdf));
}
TEST(WarpDistribution, CosineHemisphereMatchesItsPdf) {
  EXPECT_TRUE(directions_match_pdf(square_to_cosine_hemisphere, cosine_hemisphere_pdf));
}
TEST(WarpDistribution, ConcentricDiskIsUniform) { EXPECT_TRUE(disk_is_uniform(square_to_concentric_disk)); }
TEST(WarpDistribution, TriangleIsUniform) { EXPECT_TRUE(triangle_is_uniform(square_to_uniform_triangle)); }

// --- samples follow their density: the Jacobian, deterministically ----------------
//
// A warp's density is the reciprocal of its Jacobian determinant. Partial
// derivatives by Richardson-extrapolated central differences,
// (4 D(h) - D(2h)) / 3 with h = 1e-3, on a 32x32 grid of cell centres:
// truncation error O(h^4) (under 1e-5 relative even at the grid points
// nearest the poles of the sphere and the corner of the triangle, where the
// maps have a square-root singularity), float rounding ~ 2^-24 / h ~ 1e-4
// relative. So 1e-3 bounds the error of a correct warp, while a wrong
// density is off by a factor. Grid points whose stencil would straddle a seam
// are skipped: the diagonals of the concentric map (where it is not
// differentiable); so is its rim (where z = sqrt(1 - r^2) is steep).

constexpr float kH = 1e-3f;
constexpr double kJacobianTolerance = 1e-3;

bool near_concentric_seam(vec2 u) {
  const float ox = std::abs(2.0f * u.x - 1.0f), oy = std::abs(2.0f * u.y - 1.0f);
  return std::abs(ox - oy) < 8.0f * kH || std::max(ox, oy) > 0.9f;
}

template <typename Warp, typename Measure>
testing::AssertionResult jacobian_is(Warp warp, Measure density_times_jacobian, bool skip_concentric_seams) {
  std::ostringstream failures;
  int bad = 0;
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j) {
      const vec2 u((i + 0.5f) / 32.0f, (j + 0.5f) / 32.0f);
      if (skip_concentric_seams && near_concentric_seam(u)) continue;
      auto derivative = [&](vec2 e) {
        const auto d_h = (warp(u + kH * e) - warp(u - kH * e)) / (2.0f * kH);
        const auto d_2h = (warp(u + 2.0f * kH * e) - warp(u - 2.0f * kH * e)) / (4.0f * kH);
        return (4.0f * d_h - d_2h) / 3.0f;
      };
      const auto d1 = derivative(vec2(1.0f, 0.0f)), d2 = derivative(vec2(0.0f, 1.0f));
      const double v = density_times_jacobian(warp(u), d1, d2);
      if (!(std::abs(v - 1.0) <= kJacobianTolerance) && ++bad <= 5)
        failures << "u = (" << u.x << ", " << u.y << "): density * |J| = " << v << "\n";
    }
  if (bad > 0) return testing::AssertionFailure() << bad << " grid points off, e.g.\n" << failures.str();
  return testing::AssertionSuccess();
}

testing::AssertionResult direction_jacobian_matches_pdf(DirWarp warp, DirPdf pdf, bool concentric) {
  return jacobian_is(
      warp,
      [pdf](const vec3& w, const vec3& d1, const vec3& d2) {
        return double(pdf(w)) * glm::length(glm::dvec3(glm::cross(d1, d2)));
      },
      concentric);
}

// Uniform on a domain of area `area`: |det J| = area / 1.
testing::AssertionResult plane_warp_has_constant_jacobian(PlaneWarp warp, double area, bool concentric) {
  return jacobian_is(
      warp,
      [area](const vec2&, const vec2& d1, const vec2& d2) {
        return std::abs(double(d1.x) * d2.y - double(d1.y) * d2.x) / area;
      },
      concentric);
}

TEST(WarpJacobian, UniformSphereMatchesItsPdf) {
  EXPECT_TRUE(direction_jacobian_matches_pdf(square_to_uniform_sphere, sphere_pdf, false));
}
TEST(WarpJacobian, CosineHemisphereMatchesItsPdf) {
  EXPECT_TRUE(direction_jacobian_matches_pdf(square_to_cosine_hemisphere, cosine_hemisphere_pdf, true));
}
TEST(WarpJacobian, ConcentricDiskIsAreaPreserving) {
  EXPECT_TRUE(plane_warp_has_constant_jacobian(square_to_concentric_disk, kPiD, true));
}
TEST(WarpJacobian, TriangleIsAreaPreserving) {
  EXPECT_TRUE(plane_warp_has_constant_jacobian(square_to_uniform_triangle, 0.5, false));
}

// --- inverses --------------------------------------------------------------------------

// inverse(warp(u)) ~ u and warp(inverse(warp(u))) ~ warp(u) within 1e-4, on
// the 64x64 grid of cell centres and 10^4 random points, all at least 1e-3
// from the edges of the square (the seams: phi wrap-around and poles of the
// sphere, the degenerate corner of the triangle).
template <typename Warp, typename Inverse>
testing::AssertionResult inverts(Warp warp, Inverse inverse) {
  std::vector<vec2> pts;
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) pts.emplace_back((i + 0.5f) / 64.0f, (j + 0.5f) / 64.0f);
  UniformSquare rng(10);
  for (int i = 0; i < 10000; ++i) pts.push_back(vec2(1e-3f) + rng.next() * (1.0f - 2e-3f));
  for (const vec2 u : pts) {
    const auto x = warp(u);
    const vec2 v = inverse(x);
    const auto y = warp(v);
    const float du = glm::length(v - u), dx = glm::length(y - x);
    if (!(du <= 1e-4f && dx <= 1e-4f))
      return testing::AssertionFailure() << "u = (" << u.x << ", " << u.y << ") -> inverse (" << v.x << ", " << v.y
                                         << "): |du| = " << du << ", |dx| = " << dx;
  }
  return testing::AssertionSuccess();
}

TEST(WarpInverse, ConcentricDisk) { EXPECT_TRUE(inverts(square_to_concentric_disk, concentric_disk_to_square)); }
TEST(WarpInverse, CosineHemisphere) {
  EXPECT_TRUE(inverts(square_to_cosine_hemisphere, cosine_hemisphere_to_square));
}
TEST(WarpInverse, UniformSphere) { EXPECT_TRUE(inverts(square_to_uniform_sphere, uniform_sphere_to_square)); }
TEST(WarpInverse, Triangle) { EXPECT_TRUE(inverts(square_to_uniform_triangle, uniform_triangle_to_square)); }

// A sample maps back to random numbers in [0, 1)^2, including samples made
// from the extreme random numbers (next to the seams, where rounding could
// push the inverse onto 1 or below 0).
template <typename Warp, typename Inverse>
testing::AssertionResult inverse_stays_in_square(Warp warp, Inverse inverse) {
  std::vector<float> coords = {0.5f, 0.25f, 0.75f};
  for (int k = 0; k < 256; ++k) {
    coords.push_back(static_cast<float>(k) * 0x1p-24f);
    coords.push_back(1.0f - static_cast<float>(k + 1) * 0x1p-24f);
  }
  std::vector<vec2> pts;
  for (const float a : coords)
    for (const float b : coords) pts.emplace_back(a, b);
  UniformSquare rng(12);
  for (int i = 0; i < 10000; ++i) pts.push_back(rng.next());
  for (const vec2 u : pts) {
    const vec2 v = inverse(warp(u));
    if (!(v.x >= 0.0f && v.x < 1.0f && v.y >= 0.0f && v.y < 1.0f))
      return testing::AssertionFailure() << "u = (" << u.x << ", " << u.y << ") -> inverse (" << v.x << ", " << v.y
                                         << ")";
  }
  return testing::AssertionSuccess();
}

TEST(WarpInverse, UniformSphereSamplesMapBackIntoTheUnitSquare) {
  EXPECT_TRUE(inverse_stays_in_square(square_to_uniform_sphere, uniform_sphere_to_square));
}

TEST(WarpInverse, ConcentricSamplesMapBackIntoTheUnitSquare) {
  EXPECT_TRUE(inverse_stays_in_square(square_to_concentric_disk, concentric_disk_to_square));
  EXPECT_TRUE(inverse_stays_in_square(square_to_cosine_hemisphere, cosine_hemisphere_to_square));
}

TEST(WarpInverse, TriangleSamplesMapBackIntoTheUnitSquare) {
  EXPECT_TRUE(inverse_stays_in_square(square_to_uniform_triangle, uniform_triangle_to_square));
}

TEST(WarpInverse, ConcentricDiskCentreAndAxes) {
  // The centre and the ends of the axes, where the wedges meet.
  EXPECT_EQ(square_to_concentric_disk(vec2(0.5f)), vec2(0.0f));
  EXPECT_EQ(concentric_disk_to_square(vec2(0.0f)), vec2(0.5f));
  const vec2 axis_points[] = {{1.0f, 0.0f}, {0.0f, 1.0f}, {-1.0f, 0.0f}, {0.0f, -1.0f}};
  const vec2 squares[] = {{1.0f, 0.5f}, {0.5f, 1.0f}, {0.0f, 0.5f}, {0.5f, 0.0f}};
  for (int k = 0; k < 4; ++k) {
    const vec2 u = concentric_disk_to_square(axis_points[k]);
    EXPECT_NEAR(u.x, squares[k].x, 1e-6f) << k;
    EXPECT_NEAR(u.y, squares[k].y, 1e-6f) << k;
  }
}

// --- MIS helpers --------------------------------------------------------------------

TEST(WarpMis, PowerHeuristicValues) {
  EXPECT_FLOAT_EQ(power_heuristic(1.0f, 1.0f), 0.5f);
  EXPECT_FLOAT_EQ(power_heuristic(2.0f, 1.0f), 0.8f);
  EXPECT_FLOAT_EQ(power_heuristic(1.0f, 3.0f), 0.1f);
  EXPECT_FLOAT_EQ(power_heuristic(0.3f, 0.4f), 0.36f);
}

// Weights of the two techniques sum to one: each weight is a/(a+b) with
// three roundings after squaring, relative error <= 4u (u = 2^-24), plus one
// rounding for the sum: |sum - 1| <= 5u.
constexpr float kSumBound = 5.0f * 0x1p-24f;

TEST(WarpMis, PowerHeuristicSumsToOneWithItsComplement) {
  // Densities whose squares are normal floats: 1e-18 .. 1e18.
  for (int i = -18; i <= 18; ++i)
    for (int j = -18; j <= 18; ++j)
      for (const float m : {1.0f, 3.7f}) {
        const float a = m * std::pow(10.0f, static_cast<float>(i)), b = std::pow(10.0f, static_cast<float>(j));
        const float sum = power_heuristic(a, b) + power_heuristic(b, a);
        ASSERT_NEAR(sum, 1.0f, kSumBound) << "pdfs " << a << ", " << b;
      }
}

TEST(WarpMis, PowerHeuristicSumsToOneForExtremeFiniteDensities) {
  EXPECT_NEAR(power_heuristic(1e20f, 1e20f), 0.5f, kSumBound);
  EXPECT_NEAR(power_heuristic(1e20f, 2e20f), 0.2f, kSumBound);
  EXPECT_NEAR(power_heuristic(1e-30f, 1e-30f), 0.5f, kSumBound);
  const float max = std::numeric_limits<float>::max();
  for (float a = std::numeric_limits<float>::denorm_min(); a < max; a *= 7.0f)
    for (float b = std::numeric_limits<float>::denorm_min(); b < max; b *= 7.0f) {
      const float sum = power_heuristic(a, b) + power_heuristic(b, a);
      ASSERT_NEAR(sum, 1.0f, kSumBound) << "pdfs " << a << ", " << b;
    }
}

TEST(WarpMis, PowerHeuristicZeroAndInfinity) {
  const float inf = kInfinity;
  const float values[] = {0.0f, 1e-30f, 1.0f, 1e30f, std::numeric_limits<float>::max(), inf};
  for (const float a : values)
    for (const float b : values) {
      const float w = power_heuristic(a, b);
      EXPECT_TRUE(w >= 0.0f && w <= 1.0f) << "power_heuristic(" << a << ", " << b << ") = " << w;
    }
  // A technique that cannot produce the sample gets no weight; the other all.
  for (const float p : {1e-6f, 1.0f, 1e6f}) {
    EXPECT_EQ(power_heuristic(p, 0.0f), 1.0f) << p;
    EXPECT_EQ(power_heuristic(0.0f, p), 0.0f) << p;
    // A delta (infinite density) takes all the weight from a finite density.
    EXPECT_EQ(power_heuristic(inf, p), 1.0f) << p;
    EXPECT_EQ(power_heuristic(p, inf), 0.0f) << p;
  }
  EXPECT_EQ(power_heuristic(0.0f, 0.0f), 0.0f);
  EXPECT_EQ(power_heuristic(inf, 0.0f), 1.0f);
  EXPECT_EQ(power_heuristic(0.0f, inf), 0.0f);
}

TEST(WarpMis, AreaToSolidAngle) {
  // pdf_area * dist^2 / |cos|, on either side of the surface.
  EXPECT_FLOAT_EQ(area_to_solid_angle(0.5f, 2.0f, 0.25f), 8.0f);
  EXPECT_FLOAT_EQ(area_to_solid_angle(0.5f, 2.0f, -0.25f), 8.0f);
  EXPECT_FLOAT_EQ(area_to_solid_angle(3.0f, 0.5f, 1.0f), 0.75f);
}

TEST(WarpMis, AreaToSolidAngleEdgeOnIsZero) {
  for (const float cos_light : {0.0f, -0.0f})
    for (const float dist : {0.0f, 1e-3f, 1.0f, 1e6f}) {
      const float pdf = area_to_solid_angle(2.0f, dist, cos_light);
      EXPECT_EQ(pdf, 0.0f) << "dist " << dist << ", cos " << cos_light;
    }
}

// --- planted bugs: each check above must catch the bugs it is there for ----------

// Sphere: z = 1 - u (only the upper hemisphere).
vec3 sphere_half_z(vec2 u) { return square_to_uniform_sphere(vec2(0.5f * u.x, u.y)); }
// Sphere: z = 1 - 2 u^2 (non-uniform in z).
vec3 sphere_squared_z(vec2 u) { return square_to_uniform_sphere(vec2(u.x * u.x, u.y)); }
// Sphere: r = 1 - z^2 for sqrt(1 - z^2) (not unit length).
vec3 sphere_forgot_sqrt(vec2 u) {
  const vec3 w = square_to_uniform_sphere(u);
  const float r = std::sqrt(std::max(0.0f, 1.0f - w.z * w.z));
  return vec3(w.x * r, w.y * r, w.z);
}
// Sphere inverse: phi not wrapped into [0, 2 pi).
vec2 sphere_inverse_no_wrap(const vec3& w) {
  return vec2((1.0f - w.z) * 0.5f, std::atan2(w.y, w.x) * kInv2Pi);
}
// Cosine hemisphere from the polar map with r = u.x instead of sqrt(u.x).
vec3 cosine_polar_linear_r(vec2 u) {
  const float r = u.x, phi = 2.0f * kPi * u.y;
  return vec3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - r * r)));
}
// Cosine hemisphere: z = 1 - r^2 for sqrt(1 - r^2).
vec3 cosine_forgot_sqrt(vec2 u) {
  const vec2 d = square_to_concentric_disk(u);
  return vec3(d.x, d.y, 1.0f - d.x * d.x - d.y * d.y);
}
// Cosine density normalised by 2 pi; cosine density not cut at the horizon.
float cosine_pdf_over_2pi(const vec3& w) { return w.z > 0.0f ? w.z * kInv2Pi : 0.0f; }
float cosine_pdf_abs(const vec3& w) { return std::abs(w.z) * kInvPi; }
// Disk: radius squared (area not preserved).
vec2 disk_radius_squared(vec2 u) {
  const vec2 p = square_to_concentric_disk(u);
  return p * glm::length(p);
}
// Disk: mirrored (still uniform; its inverse no longer matches).
vec2 disk_mirrored(vec2 u) {
  const vec2 p = square_to_concentric_disk(u);
  return vec2(p.x, -p.y);
}
// Triangle: sqrt forgotten (b2 = 1 - u.x).
vec2 triangle_forgot_sqrt(vec2 u) { return vec2(u.y * u.x, 1.0f - u.x); }
// Triangle: the unit square, not folded into the triangle.
vec2 triangle_unfolded(vec2 u) { return u; }

TEST(WarpPlantedBugs, WrongSphereWarpIsCaught) {
  EXPECT_FALSE(directions_match_pdf(sphere_half_z, sphere_pdf));
  EXPECT_FALSE(direction_jacobian_matches_pdf(sphere_half_z, sphere_pdf, false));
  EXPECT_FALSE(directions_match_pdf(sphere_squared_z, sphere_pdf));
  EXPECT_FALSE(direction_jacobian_matches_pdf(sphere_squared_z, sphere_pdf, false));
  EXPECT_FALSE(inverts(sphere_squared_z, uniform_sphere_to_square));
  EXPECT_FALSE(samples_unit_directions(sphere_forgot_sqrt, false));
  EXPECT_FALSE(direction_jacobian_matches_pdf(sphere_forgot_sqrt, sphere_pdf, false));
  EXPECT_FALSE(inverts(square_to_uniform_sphere, sphere_inverse_no_wrap));
  EXPECT_FALSE(inverse_stays_in_square(square_to_uniform_sphere, sphere_inverse_no_wrap));
}
TEST(WarpPlantedBugs, WrongCosineWarpOrPdfIsCaught) {
  EXPECT_FALSE(directions_match_pdf(cosine_polar_linear_r, cosine_hemisphere_pdf));
  EXPECT_FALSE(direction_jacobian_matches_pdf(cosine_polar_linear_r, cosine_hemisphere_pdf, true));
  EXPECT_FALSE(samples_unit_directions(cosine_forgot_sqrt, true));
  EXPECT_FALSE(directions_match_pdf(cosine_forgot_sqrt, cosine_hemisphere_pdf));
  EXPECT_FALSE(std::abs(integral_over_sphere(cosine_pdf_over_2pi) - 1.0) <= 1e-5);
  EXPECT_FALSE(std::abs(integral_over_sphere(cosine_pdf_abs) - 1.0) <= 1e-5);
  EXPECT_FALSE(directions_match_pdf(square_to_cosine_hemisphere, cosine_pdf_over_2pi));
  EXPECT_FALSE(direction_jacobian_matches_pdf(square_to_cosine_hemisphere, cosine_pdf_over_2pi, true));
}
TEST(WarpPlantedBugs, WrongDiskWarpIsCaught) {
  EXPECT_FALSE(disk_is_uniform(disk_radius_squared));
  EXPECT_FALSE(plane_warp_has_constant_jacobian(disk_radius_squared, kPiD, true));
  EXPECT_TRUE(disk_is_uniform(disk_mirrored));  // a mirror image is still uniform ...
  EXPECT_FALSE(inverts(disk_mirrored, concentric_disk_to_square));  // ... but no longer inverted
}
TEST(WarpPlantedBugs, WrongTriangleWarpIsCaught) {
  EXPECT_FALSE(triangle_is_uniform(triangle_forgot_sqrt));
  EXPECT_FALSE(plane_warp_has_constant_jacobian(triangle_forgot_sqrt, 0.5, false));
  EXPECT_FALSE(samples_in_triangle(triangle_unfolded));
  EXPECT_FALSE(inverts(triangle_forgot_sqrt, uniform_triangle_to_square));
}

// sin_cos_quarter, the polynomial both tracers' warps use instead of libm,
// within 2 ulp of sin and cos (in double) everywhere on [-pi/4, pi/4].
TEST(SinCosQuarter, WithinTwoUlp) {
  auto ulps = [](float got, double want) {
    const float w = static_cast<float>(want);
    const double ulp = std::nextafter(std::abs(w), kInfinity) - std::abs(w);
    return std::abs(static_cast<double>(got) - want) / ulp;
  };
  double worst_sin = 0.0, worst_cos = 0.0;
  auto check = [&](float x) {
    const SinCos sc = sin_cos_quarter(x);
    worst_sin = std::max(worst_sin, ulps(sc.sin, std::sin(static_cast<double>(x))));
    worst_cos = std::max(worst_cos, ulps(sc.cos, std::cos(static_cast<double>(x))));
  };
  const float end = kPi / 4.0f;
  check(0.0f);
  // Every float in [0.75, pi/4], where the terms are largest; a geometric
  // grid of 1e-4 steps below it, down to 1e-30. Both signs.
  for (float m = end; m >= 0.75f; m = std::nextafter(m, 0.0f)) check(m), check(-m);
  for (float m = 0.75f; m > 1e-30f; m *= 1.0f - 1e-4f) check(m), check(-m);
  EXPECT_LE(worst_sin, 2.0);
  EXPECT_LE(worst_cos, 2.0);
}

}  // namespace
}  // namespace pathlab
