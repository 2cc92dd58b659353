// analytic-scenes/polygon_irradiance.h: Lambert's closed-form irradiance
// from a polygon against brute-force quadrature over the polygon's area and
// against classical closed forms; and the 2-D convex hull and convex
// clipping against known cases and Monte Carlo areas.
//
// Quadrature tolerances. The reference for polygon_form_factor is the
// composite midpoint rule on a cells × cells grid over a parametrisation of
// the polygon, (u, v) ∈ [0,1]², of the area integral
//     E/L = ∫_A cosθ_x cosθ_y / r² dA.
// For an integrand that is smooth on the grid's domain the midpoint rule's
// error has the asymptotic expansion I_h − I = C h² + O(h⁴) (Euler–Maclaurin;
// the odd powers cancel by symmetry of the midpoint), so halving the grid
// gives I_{2h} − I_h = 3 C h² + O(h⁴): the error of the fine grid is about
// |I_{2h} − I_h| / 3. Every comparison below allows |I_{2h} − I_h|, three
// times that estimate, plus 1e-12·|I| for rounding in the 10⁶-term sum
// (each row summed separately, so the sum's rounding error is ~1e-13
// relative). This needs the integrand smooth on every cell: each reference
// integrates over a region where x's horizon is not crossed inside a cell
// (see each test), and x is never on or near the polygon.
//
// Observed errors are recorded as test properties (--gtest_output=xml).
#include "analytic-scenes/polygon_irradiance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace pathlab::analytic {
namespace {

using glm::dvec2;

constexpr double kPiD = std::numbers::pi;

void record(const std::string& key, double value) {
  std::ostringstream text;
  text.precision(3);
  text << std::scientific << value;
  testing::Test::RecordProperty(key, text.str());
}

// --- brute-force reference -------------------------------------------------------

// A planar patch p(u, v), (u, v) ∈ [0,1]², with area element J(u, v) du dv.
// A parallelogram is p = o + u e1 + v e2 (J = |e1 × e2|). A triangle
// (a, b, c) uses the Duffy map p = a + u (b − a) + u v (c − b)
// (J = u |(b − a) × (c − b)|), which keeps the integrand smooth in (u, v) so
// that the midpoint rule's h² expansion holds.
struct Patch {
  dvec3 origin, e1, e2;
  bool triangle;

  dvec3 point(double u, double v) const { return origin + u * e1 + (triangle ? u * v : v) * e2; }
  double jacobian(double u) const { return (triangle ? u : 1.0) * glm::length(glm::cross(e1, e2)); }
  dvec3 unit_normal() const { return glm::normalize(glm::cross(e1, e2)); }
};

Patch parallelogram(const dvec3& o, const dvec3& e1, const dvec3& e2) { return {o, e1, e2, false}; }
Patch triangle(const dvec3& a, const dvec3& b, const dvec3& c) { return {a, b - a, c - b, true}; }

// How the integrand treats the part of the patch below x's horizon.
enum class Horizon {
  kClip,    // cosθ_x replaced by max(0, cosθ_x): only light from above counts
  kSigned,  // cosθ_x kept signed: smooth everywhere, used for differences of patches
};

// cosθ_x cosθ_y / r² at the patch point p, with cosθ_y = |N·(x − p)| / r.
double integrand(const dvec3& p, const dvec3& x, const dvec3& n, const dvec3& patch_normal, Horizon horizon) {
  const dvec3 d = p - x;
  const double r2 = glm::dot(d, d);
  double cos_x_r = glm::dot(n, d);
  if (horizon == Horizon::kClip) cos_x_r = std::max(0.0, cos_x_r);
  const double cos_y_r = std::abs(glm::dot(patch_normal, d));
  return cos_x_r * cos_y_r / (r2 * r2);
}

double midpoint_rule(const Patch& patch, const dvec3& x, const dvec3& n, Horizon horizon, int cells) {
  const dvec3 normal = patch.unit_normal();
  const double h = 1.0 / cells;
  double total = 0.0;
  for (int i = 0; i < cells; ++i) {
    const double u = (i + 0.5) * h;
    double row = 0.0;
    for (int j = 0; j < cells; ++j) row += integrand(patch.point(u, (j + 0.5) * h), x, n, normal, horizon);
    total += row * patch.jacobian(u);
  }
  return total * h * h;
}

// The fine-grid value and its tolerance |I_{2h} − I_h| + 1e-12 |I_h| (see the
// file comment), and for the record the Richardson extrapolation
// (4 I_h − I_{2h}) / 3, which cancels the h² term: its error is O(h⁴).
struct Reference {
  double value;
  double tolerance;
  double extrapolated;
};

constexpr int kCells = 1000;

Reference brute_force(const Patch& patch, const dvec3& x, const dvec3& n, Horizon horizon = Horizon::kClip) {
  const double fine = midpoint_rule(patch, x, n, horizon, kCells);
  const double coarse = midpoint_rule(patch, x, n, horizon, kCells / 2);
  return {fine, std::abs(coarse - fine) + 1e-12 * std::abs(fine), (4.0 * fine - coarse) / 3.0};
}

std::vector<dvec3> corners(const Patch& patch) {
  if (patch.triangle) return {patch.origin, patch.origin + patch.e1, patch.origin + patch.e1 + patch.e2};
  return {patch.origin, patch.origin + patch.e1, patch.origin + patch.e1 + patch.e2, patch.origin + patch.e2};
}

std::vector<dvec3> reversed(std::vector<dvec3> polygon) {
  std::reverse(polygon.begin(), polygon.end());
  return polygon;
}

void expect_matches(const std::string& name, double value, const Reference& ref) {
  EXPECT_NEAR(value, ref.value, ref.tolerance) << name;
  record(name + "_error", std::abs(value - ref.value));
  record(name + "_tolerance", ref.tolerance);
  record(name + "_extrapolated_error", std::abs(value - ref.extrapolated));
}

// π × the classical form factor from a differential area to a parallel
// a × b rectangle, the area's normal passing through one corner of the
// rectangle at distance c (Howell, "A Catalog of Radiation Heat Transfer
// Configuration Factors"):
//   πF = ½ [ A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²) atan(A/√(1+B²)) ],
// A = a/c, B = b/c.
double corner_rectangle_closed_form(double a, double b, double c) {
  const double A = a / c, B = b / c;
  const double sa = std::sqrt(1.0 + A * A), sb = std::sqrt(1.0 + B * B);
  return 0.5 * (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb));
}

// --- polygon_form_factor -----------------------------------------------------------

const dvec3 kOrigin(0.0);
const dvec3 kUp(0.0, 0.0, 1.0);

TEST(PolygonIrradiance, UnitSquareFacingPoint) {
  const Patch square = parallelogram({-0.5, -0.5, 1.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0});
  const double value = polygon_form_factor(corners(square), kOrigin, kUp);
  expect_matches("unit_square", value, brute_force(square, kOrigin, kUp));
  // By symmetry, four corner rectangles 0.5 × 0.5 at distance 1. Only
  // rounding separates the two closed forms: 1e-14 relative.
  EXPECT_NEAR(value, 4.0 * corner_rectangle_closed_form(0.5, 0.5, 1.0), 1e-14 * value);
}

TEST(PolygonIrradiance, RectangleAboveCornerMatchesClosedForm) {
  const double a = 1.3, b = 0.6, c = 0.8;
  const std::vector<dvec3> rect = {{0, 0, c}, {a, 0, c}, {a, b, c}, {0, b, c}};
  const double value = polygon_form_factor(rect, kOrigin, kUp);
  const double expected = corner_rectangle_closed_form(a, b, c);
  EXPECT_NEAR(value, expected, 1e-14 * expected);  // rounding only
  record("corner_rectangle_error", std::abs(value - expected));
}

TEST(PolygonIrradiance, SmallDistantPolygonKeepsPrecision) {
  // A 1 × 1 square at distance 1e4 along a skew direction w, off-centre,
  // seen with n = w: the corner formula by inclusion–exclusion in the
  // frame (u, v, w). Vertex coordinates of size 1e4 are themselves rounded
  // by ~1e-12 of the square's size, so the data fix the answer only to about
  // 1e-12 relative; 1e-10 allows a hundredfold. (Cross products of the
  // nearly parallel directions to the vertices would lose ~1e-9 here.)
  const dvec3 w = glm::normalize(dvec3(1.0, 1.0, 1.0));
  const dvec3 u = glm::normalize(glm::cross(kUp, w));
  const dvec3 v = glm::cross(w, u);
  const double h = 1e4;
  const auto at = [&](double a, double b) { return a * u + b * v + h * w; };
  const std::vector<dvec3> square = {at(0.3, 0.2), at(1.3, 0.2), at(1.3, 1.2), at(0.3, 1.2)};
  const double expected = corner_rectangle_closed_form(1.3, 1.2, h) - corner_rectangle_closed_form(0.3, 1.2, h) -
                          corner_rectangle_closed_form(1.3, 0.2, h) + corner_rectangle_closed_form(0.3, 0.2, h);
  const double value = polygon_form_factor(square, kOrigin, w);
  EXPECT_NEAR(value, expected, 1e-10 * expected);
  record("distant_square_relative_error", std::abs(value - expected) / expected);
}

TEST(PolygonIrradiance, TiltedOffsetTriangle) {
  // Wholly above x's horizon, tilted against both x's normal and the line
  // of sight, and off to one side: no symmetry to hide behind.
  const Patch tri = triangle({0.3, -0.2, 1.1}, {1.5, 0.4, 0.8}, {0.2, 1.3, 1.9});
  const dvec3 x(0.1, 0.05, -0.1);
  const dvec3 n = glm::normalize(dvec3(0.2, -0.1, 1.0));
  for (const dvec3& v : corners(tri)) ASSERT_GT(glm::dot(n, v - x), 0.0);
  expect_matches("tilted_triangle", polygon_form_factor(corners(tri), x, n), brute_force(tri, x, n));
}

TEST(PolygonIrradiance, RectanglePartlyBelowHorizonIsClipped) {
  // A tilted rectangle o + u e1 + v e2 and a normal n ⊥ e1: x's horizon
  // plane then meets the rectangle's plane in a line parallel to e1, here at
  // v = 0.75 (n·(o + 0.75 e2 − x) = 0, solved for n's y component). The line
  // lies on a grid line of both the 1000- and the 500-cell grids, so every
  // cell lies wholly on one side: below it the clipped integrand and the
  // truth are both 0, above it smooth, and the h² expansion holds.
  const Patch rect = parallelogram({-0.7, -1.0, 1.0}, {2.0, 0.0, 0.0}, {0.0, 2.0, 0.5});
  const dvec3 n = glm::normalize(dvec3(0.0, -2.75, 1.0));  // 0.5·(−2.75) + 1.375 = 0
  const Reference ref = brute_force(rect, kOrigin, n);
  const double value = polygon_form_factor(corners(rect), kOrigin, n);
  expect_matches("rectangle_below_horizon", value, ref);
  // Without the clip the part below would subtract: the signed integral is
  // far from the answer, so the test has power against a missing clip.
  const Reference signed_ref = brute_force(rect, kOrigin, n, Horizon::kSigned);
  EXPECT_GT(std::abs(signed_ref.value - ref.value), 100.0 * ref.tolerance);
}

TEST(PolygonIrradiance, DiagonalHorizonCutsOffCorner) {
  // The horizon crosses the rectangle diagonally, cutting off the corner
  // o (below). The reference integrates the signed integrand, smooth
  // everywhere, over the rectangle minus over the corner triangle: that is
  // the integral over the part above, with the h² expansion valid for both
  // terms (tolerances add).
  const dvec3 o(-1.0, -0.8, 1.0), e1(2.0, 0.0, 0.3), e2(0.0, 1.8, -0.2);
  const dvec3 n = glm::normalize(dvec3(0.9, 0.7, 1.0));
  const auto height = [&](const dvec3& p) { return glm::dot(n, p); };  // x is the origin
  ASSERT_LT(height(o), 0.0);
  ASSERT_GT(height(o + e1), 0.0);
  ASSERT_GT(height(o + e2), 0.0);
  // Where the height, linear along each edge from o, vanishes.
  const dvec3 p1 = o + e1 * (height(o) / (height(o) - height(o + e1)));
  const dvec3 p2 = o + e2 * (height(o) / (height(o) - height(o + e2)));
  const Reference whole = brute_force(parallelogram(o, e1, e2), kOrigin, n, Horizon::kSigned);
  const Reference corner = brute_force(triangle(o, p1, p2), kOrigin, n, Horizon::kSigned);
  const Reference above = {whole.value - corner.value, whole.tolerance + corner.tolerance,
                           whole.extrapolated - corner.extrapolated};
  expect_matches("diagonal_horizon", polygon_form_factor(corners(parallelogram(o, e1, e2)), kOrigin, n), above);
}

TEST(PolygonIrradiance, BothWindingsAgree) {
  // Reversing the vertices negates every a×b exactly and leaves every θ: the
  // sum negates up to the order of summation and the rounding of the
  // horizon crossings. Its terms are each at most π in size and carry
  // ~1e-16 relative rounding, so with at most a dozen of them the results
  // agree to 1e-14 absolute (the values are at most π).
  const dvec3 n = glm::normalize(dvec3(0.9, 0.7, 1.0));
  const std::vector<std::vector<dvec3>> polygons = {
      corners(triangle({0.3, -0.2, 1.1}, {1.5, 0.4, 0.8}, {0.2, 1.3, 1.9})),
      corners(parallelogram({-1.0, -0.8, 1.0}, {2.0, 0.0, 0.3}, {0.0, 1.8, -0.2})),  // crosses the horizon
      {{-1, -1, 1}, {2, -1, 1}, {2, 0, 1}, {0, 0, 1}, {0, 2, 1}, {-1, 2, 1}},         // concave L
  };
  for (const auto& polygon : polygons) {
    const double forward = polygon_form_factor(polygon, kOrigin, n);
    EXPECT_GT(forward, 0.0);
    EXPECT_NEAR(polygon_form_factor(reversed(polygon), kOrigin, n), forward, 1e-14);
  }
}

TEST(PolygonIrradiance, PolygonInPointsPlaneIsZero) {
  // x's tangent plane, containing x, with x inside the polygon ...
  const std::vector<dvec3> around = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  EXPECT_EQ(polygon_form_factor(around, kOrigin, kUp), 0.0);
  // ... a plane through x that is not the tangent plane, x outside ...
  const dvec3 n = glm::normalize(dvec3(0.3, 0.0, 1.0));
  const std::vector<dvec3> through = {{1, 0, 1}, {2, 0, 2}, {2, 1, 2}, {1, 1, 1}};  // plane z = x
  EXPECT_EQ(polygon_form_factor(through, kOrigin, n), 0.0);
  EXPECT_GT(polygon_form_factor(through, dvec3(0.0, 0.0, 0.5), n), 0.0);  // control: off the plane
  // ... and x inside, with the plane tilted against n.
  const std::vector<dvec3> tilted = {{-1, -1, -1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, -1}};  // plane z = x
  EXPECT_EQ(polygon_form_factor(tilted, kOrigin, n), 0.0);
  EXPECT_EQ(polygon_form_factor(tilted, kOrigin, kUp), 0.0);
}

TEST(PolygonIrradiance, RoundedPointInThePlaneIsZero) {
  // A point computed as a combination of the vertices misses their plane by
  // rounding only: it still counts as in the plane.
  const std::vector<dvec3> tri = {{0.3, -0.2, 1.1}, {1.5, 0.4, 0.8}, {0.2, 1.3, 1.9}};
  const dvec3 x = 0.3 * tri[0] + 0.3 * tri[1] + 0.4 * tri[2];
  EXPECT_EQ(polygon_form_factor(tri, x, kUp), 0.0);
  EXPECT_EQ(polygon_form_factor(tri, x + dvec3(5.0, -3.0, 0.7) * 1e-17, kUp), 0.0);
}

TEST(PolygonIrradiance, PointJustOffThePlaneSeesHalfSpace) {
  // x at ε = 1e-9 below a unit square, its foot r = 0.3 from the nearest
  // edge. Every direction with ω_z ≥ ε/r (above x, whose own plane is
  // z = 1 − ε) meets the plane z = 1 within r of the foot, inside the
  // square, so the value misses at most the band 0 < ω_z < ε/r of the upper
  // hemisphere: solid angle 2π ε/r, weight n·ω ≤ 1. Against the infinite
  // plane's π (n = z) and π (1 + cos 45°)/2 (n tilted 45°, the part of its
  // hemisphere above z = 1 − ε), allow 2π ε/r ≈ 2.1e-8.
  const std::vector<dvec3> square = {{-0.5, -0.5, 1}, {0.5, -0.5, 1}, {0.5, 0.5, 1}, {-0.5, 0.5, 1}};
  const double eps = 1e-9, r = 0.3;
  const dvec3 x(0.1, 0.2, 1.0 - eps);
  const double bound = 2.0 * kPiD * eps / r;
  EXPECT_NEAR(polygon_form_factor(square, x, kUp), kPiD, bound);
  const dvec3 tilted = glm::normalize(dvec3(1.0, 0.0, 1.0));
  const double half_space = 0.5 * kPiD * (1.0 + std::numbers::sqrt2 / 2.0);
  const double value = polygon_form_factor(square, x, tilted);
  EXPECT_NEAR(value, half_space, bound);
  record("near_plane_error", std::abs(value - half_space));
}

TEST(PolygonIrradiance, BelowHorizonAndDegenerateAreZero) {
  const std::vector<dvec3> below = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}};
  EXPECT_EQ(polygon_form_factor(below, kOrigin, kUp), 0.0);
  // Touching the horizon along one edge: the clipped polygon is a segment.
  const std::vector<dvec3> touching = {{-1, 1, 0}, {1, 1, 0}, {1, 2, -1}, {-1, 2, -1}};
  EXPECT_EQ(polygon_form_factor(touching, kOrigin, kUp), 0.0);
  EXPECT_EQ(polygon_form_factor({}, kOrigin, kUp), 0.0);
  const std::vector<dvec3> point = {{0, 0, 1}};
  const std::vector<dvec3> segment = {{0, 0, 1}, {1, 0, 1}};
  const std::vector<dvec3> collinear = {{0, 0, 1}, {1, 0, 1}, {3, 0, 1}};
  EXPECT_EQ(polygon_form_factor(point, kOrigin, kUp), 0.0);
  EXPECT_EQ(polygon_form_factor(segment, kOrigin, kUp), 0.0);
  EXPECT_EQ(polygon_form_factor(collinear, kOrigin, kUp), 0.0);
  // A repeated vertex adds an edge seen end-on, which contributes nothing.
  const std::vector<dvec3> tri = {{0.3, -0.2, 1.1}, {1.5, 0.4, 0.8}, {0.2, 1.3, 1.9}};
  const std::vector<dvec3> repeated = {tri[0], tri[1], tri[1], tri[2]};
  EXPECT_EQ(polygon_form_factor(repeated, kOrigin, kUp), polygon_form_factor(tri, kOrigin, kUp));
}

TEST(PolygonIrradiance, HugeSquareApproachesWholeHemisphere) {
  // A square of side 1e4 at height h = 1 contains the disk of radius
  // R = 5e3, whose value is π R²/(R² + h²); the whole hemisphere gives π. So
  // π − value lies in [0, π h²/(R² + h²)] ≈ [0, 1.3e-7] (plus rounding).
  const double half = 5e3;
  const std::vector<dvec3> square = {{-half, -half, 1}, {half, -half, 1}, {half, half, 1}, {-half, half, 1}};
  const double value = polygon_form_factor(square, kOrigin, kUp);
  EXPECT_NEAR(value, kPiD, 1e-3);
  EXPECT_LE(value, kPiD + 1e-12);
  EXPECT_GE(value, kPiD * half * half / (half * half + 1.0) - 1e-12);
  record("huge_square_error", kPiD - value);
}

TEST(PolygonIrradiance, RegularPolygonsBracketTheDisk) {
  // A disk of radius R centred at height h above x gives π R²/(R² + h²). A
  // regular k-gon inscribed in it gives less, one circumscribed more, and
  // both converge to it as 1/k².
  const double radius = 0.8, h = 0.6;
  const double disk = kPiD * radius * radius / (radius * radius + h * h);
  for (int k : {3, 8, 64, 1024}) {
    std::vector<dvec3> inscribed, circumscribed;
    const double outer = radius / std::cos(kPiD / k);
    for (int i = 0; i < k; ++i) {
      const double phi = 2.0 * kPiD * i / k;
      inscribed.emplace_back(radius * std::cos(phi), radius * std::sin(phi), h);
      circumscribed.emplace_back(outer * std::cos(phi), outer * std::sin(phi), h);
    }
    const double inner_value = polygon_form_factor(inscribed, kOrigin, kUp);
    const double outer_value = polygon_form_factor(circumscribed, kOrigin, kUp);
    EXPECT_LT(inner_value, disk) << k;
    EXPECT_GT(outer_value, disk) << k;
    if (k == 1024) {
      // The circumscribed k-gon has 1/cos²(π/k) ≈ 1 + (π/k)² times the
      // inscribed one's area, the extra lying at the rim where the weight
      // cos²/r² is smallest: the values differ by less than (π/k)² ≈ 9.4e-6
      // of the disk's (allowed twice that).
      EXPECT_LT(outer_value - inner_value, 2.0 * (kPiD / k) * (kPiD / k) * disk);
      record("disk_bracket_width", outer_value - inner_value);
    }
  }
}

TEST(PolygonIrradiance, AdditiveOverPieces) {
  // Lambert's sum runs over the boundary, and the shared edge of two pieces
  // appears once in each direction, so the pieces' values add up to the
  // whole exactly apart from rounding. The rounding is relative to the
  // terms of the sums (each at most π, a dozen or so of them), not to the
  // result, which can be much smaller when they cancel: 1e-14 absolute.
  const dvec3 x(0.2, -0.1, 0.0);
  const dvec3 n = glm::normalize(dvec3(0.4, 0.3, 1.0));
  // A square split into two rectangles, wholly above the horizon.
  const std::vector<dvec3> whole = {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
  const std::vector<dvec3> left = {{-1, -1, 1}, {0.3, -1, 1}, {0.3, 1, 1}, {-1, 1, 1}};
  const std::vector<dvec3> right = {{0.3, -1, 1}, {1, -1, 1}, {1, 1, 1}, {0.3, 1, 1}};
  const double sum = polygon_form_factor(left, x, n) + polygon_form_factor(right, x, n);
  const double total = polygon_form_factor(whole, x, n);
  EXPECT_NEAR(sum, total, 1e-14);
  record("additivity_error", std::abs(sum - total));

  // A concave L is the union of two rectangles. The horizon (x + y = 1 in
  // the L's plane z = 1) crosses both arms and leaves the corner below, so
  // the clipped L is two pieces joined by a bridge edge along the horizon,
  // traversed once each way.
  const dvec3 steep = glm::normalize(dvec3(1.0, 1.0, -1.0));
  const std::vector<dvec3> ell = {{-1, -1, 1}, {2, -1, 1}, {2, 0, 1}, {0, 0, 1}, {0, 2, 1}, {-1, 2, 1}};
  const std::vector<dvec3> bottom = {{-1, -1, 1}, {2, -1, 1}, {2, 0, 1}, {-1, 0, 1}};
  const std::vector<dvec3> top = {{-1, 0, 1}, {0, 0, 1}, {0, 2, 1}, {-1, 2, 1}};
  const double ell_value = polygon_form_factor(ell, kOrigin, steep);
  const double ell_sum = polygon_form_factor(bottom, kOrigin, steep) + polygon_form_factor(top, kOrigin, steep);
  EXPECT_GT(ell_value, 0.0);
  EXPECT_NEAR(ell_value, ell_sum, 1e-14);
  record("additivity_concave_error", std::abs(ell_value - ell_sum));
}

// --- convex_hull -------------------------------------------------------------------


double turn(const dvec2& o, const dvec2& a, const dvec2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// Coordinates are O(1): a cross product of differences is rounded by a few
// 1e-16. A point counts as inside a convex CCW polygon when no edge sees it
// more than kSlack to its right (1e-12: a thousandfold that rounding, and far
// below any real violation in these tests).
constexpr double kSlack = 1e-12;

bool inside(const std::vector<dvec2>& convex, const dvec2& p) {
  for (std::size_t i = 0; i < convex.size(); ++i)
    if (turn(convex[i], convex[(i + 1) % convex.size()], p) < -kSlack) return false;
  return true;
}

void expect_strictly_convex_ccw(const std::vector<dvec2>& polygon) {
  ASSERT_GE(polygon.size(), 3u);
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const dvec2& prev = polygon[(i + polygon.size() - 1) % polygon.size()];
    const dvec2& next = polygon[(i + 1) % polygon.size()];
    EXPECT_GT(turn(prev, polygon[i], next), 0.0) << "vertex " << i;
  }
}

TEST(PolygonIrradianceHull, GridWithDuplicatesGivesItsCorners) {
  std::vector<dvec2> points;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) points.emplace_back(i, j);
  points.insert(points.end(), points.begin(), points.begin() + 30);  // duplicates
  std::shuffle(points.begin(), points.end(), std::mt19937_64(7));
  const std::vector<dvec2> hull = convex_hull(points);
  const std::vector<dvec2> expected = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  EXPECT_EQ(hull, expected);
  EXPECT_EQ(signed_area(hull), 100.0);
}

TEST(PolygonIrradianceHull, RandomPointsLieInsideCounterClockwiseHull) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> coord(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<dvec2> points;
    for (int i = 0; i < 2000; ++i) {  // a disk's worth of points: a hull of many vertices
      const dvec2 p(2.0 * coord(rng) - 1.0, 2.0 * coord(rng) - 1.0);
      if (glm::dot(p, p) <= 1.0) points.push_back(p);
    }
    const std::vector<dvec2> hull = convex_hull(points);
    expect_strictly_convex_ccw(hull);
    for (const dvec2& v : hull) EXPECT_NE(std::find(points.begin(), points.end(), v), points.end());
    for (const dvec2& p : points) EXPECT_TRUE(inside(hull, p)) << p.x << ", " << p.y;
    // Inscribed in the unit disk, and with ~1500 points it misses little of it.
    EXPECT_LT(signed_area(hull), kPiD);
    EXPECT_GT(signed_area(hull), 0.95 * kPiD);
  }
  // Random points in the unit square together with its corners: the hull is
  // the square.
  std::vector<dvec2> points = {{1, 1}, {0, 0}, {0, 1}, {1, 0}};
  for (int i = 0; i < 1000; ++i) points.emplace_back(coord(rng), coord(rng));
  const std::vector<dvec2> hull = convex_hull(points);
  const std::vector<dvec2> square = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_EQ(hull, square);
  EXPECT_EQ(signed_area(hull), 1.0);
}

TEST(PolygonIrradianceHull, DegenerateInputs) {
  EXPECT_TRUE(convex_hull({}).empty());
  const std::vector<dvec2> one = {{1, 2}};
  EXPECT_EQ(convex_hull({{1, 2}, {1, 2}, {1, 2}}), one);
  const std::vector<dvec2> ends = {{0, 0}, {3, 3}};
  EXPECT_EQ(convex_hull({{2, 2}, {0, 0}, {3, 3}, {1, 1}, {2, 2}}), ends);
  // Collinear points along an edge are not vertices.
  const std::vector<dvec2> tri = {{0, 0}, {4, 0}, {0, 4}};
  EXPECT_EQ(convex_hull({{0, 0}, {1, 0}, {2, 0}, {4, 0}, {2, 2}, {0, 4}, {0, 2}, {1, 1}}), tri);
}

// --- clip_convex -------------------------------------------------------------------

// True if `polygon` is a cyclic rotation of `expected`, vertex by vertex
// within `tolerance`.
bool same_cycle(const std::vector<dvec2>& polygon, const std::vector<dvec2>& expected, double tolerance) {
  if (polygon.size() != expected.size()) return false;
  for (std::size_t shift = 0; shift < polygon.size(); ++shift) {
    bool all = true;
    for (std::size_t i = 0; i < polygon.size() && all; ++i) {
      const dvec2 d = polygon[(i + shift) % polygon.size()] - expected[i];
      all = std::abs(d.x) <= tolerance && std::abs(d.y) <= tolerance;
    }
    if (all) return true;
  }
  return false;
}

std::vector<dvec2> box(double x0, double y0, double x1, double y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

TEST(PolygonIrradianceClip, SquareAndShiftedSquareGiveRectangle) {
  const std::vector<dvec2> result = clip_convex(box(0, 0, 1, 1), box(0.5, 0.25, 1.5, 1.25));
  EXPECT_TRUE(same_cycle(result, box(0.5, 0.25, 1, 1), 0.0));
  EXPECT_EQ(signed_area(result), 0.375);
}

TEST(PolygonIrradianceClip, DisjointOrTouchingGiveEmpty) {
  EXPECT_TRUE(clip_convex(box(0, 0, 1, 1), box(2, 0, 3, 1)).empty());
  EXPECT_TRUE(clip_convex(box(0, 0, 1, 1), box(1, 0, 2, 1)).empty());      // shared edge
  EXPECT_TRUE(clip_convex(box(0, 0, 1, 1), box(1, 1, 2, 2)).empty());      // shared corner
  const std::vector<dvec2> tri = {{2, 0}, {3, 0}, {2, 1}};
  EXPECT_TRUE(clip_convex(tri, box(0, 0, 1, 1)).empty());
  EXPECT_TRUE(clip_convex(box(0, 0, 1, 1), std::vector<dvec2>{{0, 0}, {1, 1}}).empty());
}

TEST(PolygonIrradianceClip, ContainmentGivesInnerPolygon) {
  const std::vector<dvec2> inner = {{0.2, 0.3}, {0.7, 0.25}, {0.6, 0.8}, {0.3, 0.6}};
  // The subject inside: no vertex is cut, it comes back unchanged.
  EXPECT_EQ(clip_convex(inner, box(0, 0, 1, 1)), inner);
  // The clip inside: the result's vertices are intersections of the clip's
  // edge lines, equal to its vertices up to rounding of O(1) coordinates.
  EXPECT_TRUE(same_cycle(clip_convex(box(0, 0, 1, 1), inner), inner, 1e-14));
}

TEST(PolygonIrradianceClip, RandomIntersectionAreaMatchesMonteCarlo) {
  // Two random convex polygons (hulls of 10 points in overlapping disks).
  // Monte Carlo: m uniform points in a box of area B around both; the count
  // k inside both is Binomial(m, p) with p = area / B, so the estimate B k/m
  // has standard error B √(p(1 − p)/m). Allowing 5 standard errors, a correct
  // area fails with probability 5.7e-7 per pair (normal approximation, good
  // at m p ≫ 1), 1e-5 for the 20 pairs; the seed is fixed in any case.
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto random_convex = [&](const dvec2& centre) {
    std::vector<dvec2> points;
    for (int i = 0; i < 10; ++i) {
      const double r = std::sqrt(unit(rng)), phi = 2.0 * kPiD * unit(rng);
      points.push_back(centre + r * dvec2(std::cos(phi), std::sin(phi)));
    }
    return convex_hull(points);
  };
  constexpr int kSamples = 200000;
  double worst_z = 0.0;
  for (int pair = 0; pair < 20; ++pair) {
    const std::vector<dvec2> a = random_convex({0.0, 0.0});
    const std::vector<dvec2> b = random_convex({0.6 * unit(rng), 0.6 * unit(rng)});
    const std::vector<dvec2> both = clip_convex(a, b);
    ASSERT_FALSE(both.empty());
    expect_strictly_convex_ccw(both);
    for (const dvec2& v : both) EXPECT_TRUE(inside(a, v) && inside(b, v));
    const double area = signed_area(both);
    EXPECT_NEAR(signed_area(clip_convex(b, a)), area, 1e-14);  // same region, other order

    const dvec2 lo(-1.0, -1.0), hi(1.6, 1.6);  // holds both disks
    const double box_area = (hi.x - lo.x) * (hi.y - lo.y);
    int hits = 0;
    for (int i = 0; i < kSamples; ++i) {
      const dvec2 p = lo + (hi - lo) * dvec2(unit(rng), unit(rng));
      if (inside(a, p) && inside(b, p)) ++hits;
    }
    const double p_hat = static_cast<double>(hits) / kSamples;
    const double estimate = box_area * p_hat;
    const double standard_error = box_area * std::sqrt(p_hat * (1.0 - p_hat) / kSamples);
    EXPECT_NEAR(area, estimate, 5.0 * standard_error) << "pair " << pair;
    worst_z = std::max(worst_z, std::abs(area - estimate) / standard_error);
  }
  record("monte_carlo_worst_z", worst_z);
}

}  // namespace
}  // namespace pathlab::analytic
