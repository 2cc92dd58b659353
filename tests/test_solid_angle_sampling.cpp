// light_sampling: solid_angle (core/sampling_spherical.h, core/light_sampler.h):
// the directions LightSampler::sample() draws have the density pdf() reports,
// by chi-square over bins of the light's solid angle; that density integrates
// to the light's pick probability; the solid angle of a triangle and the
// irradiance estimates meet closed forms; the variance is lower than area
// sampling's near a light; numerical extremes give finite results.
//
// Bins. For a triangle, an n x n barycentric grid of sub-triangles tiles it
// exactly; each direction is binned by where its ray meets the triangle's
// plane (double), so the bins are the spherical sub-triangles they subtend.
// For a sphere, bins of equal solid angle in (1 - cos theta, phi) about the
// axis towards its centre tile the cone it subtends (from outside) or the
// whole sphere of directions (from inside). Every configuration has a second
// light elsewhere, so the pick probability is not 1; a sample of the other
// light goes to one more bin whose expected count is N minus the rest, so a
// pdf() without the pick probability fails too.
//
// Expected counts: N times the integral of pdf() over the bin, by a rule that
// is exact for a constant density (the solid angle of each of m x m
// sub-sub-triangles, Van Oosterom & Strackee in double, times pdf() at its
// centroid) and second order otherwise; the area-density configurations
// compare m with 2m and the difference is far below the counts' noise (1e-4
// relative against >= 1e-2). Level: alpha = 0.01 family-wise, Šidák over all
// configurations of this file.
#include "analytic-scenes/polygon_irradiance.h"
#include "core/compiled_scene.h"
#include "core/rng.h"
#include "core/sampling_spherical.h"
#include "tests/stat_util.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <ostream>
#include <string>
#include <vector>

namespace pathlab {
namespace {

constexpr double kPiD = std::numbers::pi;
constexpr double kAlpha = 0.01;
// Chi-square tests (triangles + spheres) and z-tests (irradiance) in this file.
constexpr double kComparisons = 16 + 6 + 4 * 2 + 3 * 2;

float uniform(std::uint64_t stream, std::uint64_t k) { return to_unit_float(mix64(mix64(stream) ^ k)); }

// A second emitter (material 1, a triangle of area 0.5 in the plane x = 50,
// which no ref lies in) of a quarter of the power of the light under test
// (area `area`, radiance 1), so that the pick probability is not 1.
void add_other_light(Scene& scene, double area) {
  scene.materials.push_back(Material{"other", MaterialType::Emissive, Spectrum(0.0f), Spectrum(float(0.25 * area / 0.5)), true});
  Shape o;
  o.description = "other";
  o.material = 1;
  o.mesh = {{{50, 0, 0}, {50, 1, 0}, {50, 0, 1}}, {{0, 1, 2}}};
  scene.shapes.push_back(o);
}

// A scene of one emitting triangle (material 0, two-sided unless told) and a
// second light, a small triangle far to the side with a quarter of its power,
// so that the first light's pick probability is about 0.8.
Scene triangle_scene(const std::array<vec3, 3>& tri, LightSampling mode, bool two_sided = true) {
  Scene scene;
  scene.name = "one-triangle";
  scene.render.light_sampling = mode;
  Material m{"light", MaterialType::Emissive, Spectrum(0.0f), Spectrum(1.0f), two_sided};
  scene.materials.push_back(m);
  Shape s;
  s.description = "light";
  s.mesh = {{tri[0], tri[1], tri[2]}, {{0, 1, 2}}};
  scene.shapes.push_back(s);
  add_other_light(scene, 0.5 * glm::length(glm::cross(dvec3(tri[1] - tri[0]), dvec3(tri[2] - tri[0]))));
  return scene;
}

Scene sphere_scene(vec3 center, float radius, LightSampling mode) {
  Scene scene;
  scene.name = "one-sphere";
  scene.render.light_sampling = mode;
  scene.materials.push_back(Material{"light", MaterialType::Emissive, Spectrum(0.0f), Spectrum(1.0f), true});
  Shape s;
  s.description = "light";
  s.kind = Shape::Kind::Sphere;
  s.center = center;
  s.radius = radius;
  scene.shapes.push_back(s);
  add_other_light(scene, 4.0 * kPiD * radius * radius);
  return scene;
}

// The barycentric sub-triangles of an n x n grid: cell (i, j, upper).
struct Grid {
  int n;
  int cells() const { return n * n; }
  // The cell of barycentrics (b1, b2), clamped into the triangle.
  int cell(double b1, double b2) const {
    b1 = std::clamp(b1, 0.0, 1.0), b2 = std::clamp(b2, 0.0, 1.0);
    int i = std::min(n - 1, static_cast<int>(b1 * n)), j = std::min(n - 1, static_cast<int>(b2 * n));
    if (i + j > n - 1) {  // rounding past the hypotenuse
      const int over = i + j - (n - 1);
      (i >= j ? i : j) -= over;
    }
    const double f1 = b1 * n - i, f2 = b2 * n - j;
    const bool upper = f1 + f2 > 1.0 && i + j <= n - 2;
    return index(i, j, upper);
  }
  // Lower cells first (i + j <= n - 1), then the upper ones (i + j <= n - 2).
  int index(int i, int j, bool upper) const {
    int k = 0;
    if (!upper) {
      for (int a = 0; a < i; ++a) k += n - a;
      return k + j;
    }
    k = n * (n + 1) / 2;
    for (int a = 0; a < i; ++a) k += n - 1 - a;
    return k + j;
  }
  // The corners (in barycentrics) of cell (i, j, upper).
  std::array<glm::dvec2, 3> corners(int i, int j, bool upper) const {
    const double h = 1.0 / n;
    if (!upper) return {glm::dvec2(i * h, j * h), glm::dvec2((i + 1) * h, j * h), glm::dvec2(i * h, (j + 1) * h)};
    return {glm::dvec2((i + 1) * h, (j + 1) * h), glm::dvec2(i * h, (j + 1) * h), glm::dvec2((i + 1) * h, j * h)};
  }
  template <typename F>
  void for_each(F f) const {
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j <= n - 1; ++j) {
        f(i, j, false);
        if (i + j <= n - 2) f(i, j, true);
      }
  }
};

struct TriangleCase {
  std::string name;
  std::array<vec3, 3> tri;
  vec3 ref;
  bool spherical;  // what the fallback rule should choose
};

void PrintTo(const TriangleCase& c, std::ostream* os) { *os << c.name; }

std::vector<TriangleCase> triangle_cases() {
  const std::array<vec3, 3> unit{vec3(-1, -1, 0), vec3(1, -1, 0), vec3(0, 1, 0)};
  std::vector<TriangleCase> c;
  c.push_back({"facing", unit, vec3(0.1f, 0.2f, 2.0f), true});
  c.push_back({"oblique", unit, vec3(3.0f, 0.5f, 1.0f), true});
  c.push_back({"close_above", unit, vec3(0.0f, -0.3f, 0.05f), true});
  c.push_back({"closer_above", unit, vec3(0.0f, -0.3f, 0.03f), true});            // Omega 6.03
  c.push_back({"nearly_hemisphere", unit, vec3(0.0f, -0.3f, 0.01f), true});       // Omega 6.199
  c.push_back({"very_close_above", unit, vec3(0.0f, -0.3f, 0.002f), false});  // Omega 6.27 > 6.2: by area
  c.push_back({"grazing_beside", unit, vec3(1.6f, 0.3f, 0.001f), true});
  c.push_back({"behind", unit, vec3(0.2f, 0.1f, -0.7f), true});
  c.push_back({"right_angle_corner", {vec3(0, 0, 0), vec3(2, 0, 0), vec3(0, 0, 2)}, vec3(0.01f, 0.5f, 0.01f), true});
  c.push_back({"sliver", {vec3(0, 0, 0), vec3(1, 0, 0), vec3(0.5f, 0.001f, 0.0f)}, vec3(0.4f, 0.3f, 0.3f), true});
  c.push_back({"needle", {vec3(0, 0, 0), vec3(1, 0, 0), vec3(1.0f, 0.0005f, 0.0f)}, vec3(-0.2f, 0.2f, 0.3f), true});
  c.push_back({"obtuse", {vec3(0, 0, 0), vec3(3, 0, 0), vec3(1.5f, 0.05f, 0.0f)}, vec3(1.5f, -0.2f, 0.4f), true});
  c.push_back({"far_above_threshold", unit, vec3(0.0f, 0.0f, 600.0f), true});  // Omega ~ 5.6e-6
  c.push_back({"far_below_threshold", unit, vec3(0.0f, 0.0f, 3000.0f), false});  // Omega ~ 2.2e-7
  c.push_back({"tiny", {vec3(0, 0, 0), vec3(1e-3f, 0, 0), vec3(0, 1e-3f, 0)}, vec3(0.0f, 0.0f, 1.0f), false});
  c.push_back({"shifted_far_from_origin",
               {vec3(1000.0f, 2000.0f, 0.0f), vec3(1001.0f, 2000.0f, 0.0f), vec3(1000.0f, 2001.0f, 0.5f)},
               vec3(1000.3f, 2000.2f, 1.0f), true});
  return c;
}

// Integral of pdf() over the spherical image of the barycentric triangle
// `corners`, by m x m sub-triangles: for a density constant in solid angle
// (`spherical`), each one's solid angle times pdf() at its centroid; for a
// density constant in area, its area times pdf() times cos / d^2 at the
// centroid. Each rule is exact for its kind of density; the test picks it by
// its own evaluation of the fallback rule, not by asking the sampler.
double integrate_pdf(const LightSampler& lights, const Triangle& t, const vec3& ref,
                     const std::array<glm::dvec2, 3>& corners, int m, bool spherical) {
  const dvec3 o(ref), p0(t.p0), p1(t.p1), p2(t.p2);
  auto at = [&](const glm::dvec2& b) { return (1.0 - b.x - b.y) * p0 + b.x * p1 + b.y * p2; };
  const dvec3 c0 = at(corners[0]), e1 = at(corners[1]) - c0, e2 = at(corners[2]) - c0;
  double sum = 0.0;
  const Grid sub{m};
  sub.for_each([&](int i, int j, bool upper) {
    const auto k = sub.corners(i, j, upper);
    const dvec3 a = c0 + k[0].x * e1 + k[0].y * e2, b = c0 + k[1].x * e1 + k[1].y * e2,
                c = c0 + k[2].x * e1 + k[2].y * e2;
    Surfel hit;
    hit.shape = 0;
    hit.prim = 0;
    const dvec3 centroid = (a + b + c) / 3.0;
    hit.p = vec3(centroid);
    hit.n = t.n;
    const double pdf = double(lights.pdf(ref, hit));
    if (spherical) {
      sum += spherical_triangle_solid_angle(a - o, b - o, c - o) * pdf;
    } else {
      const dvec3 d = centroid - o;
      const double d2 = glm::dot(d, d);
      const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
      sum += area * pdf * std::abs(glm::dot(dvec3(t.n), d)) / (d2 * std::sqrt(d2));
    }
  });
  return sum;
}

class TriangleChi2 : public testing::TestWithParam<TriangleCase> {};

TEST_P(TriangleChi2, DirectionsHaveTheDensityPdfReports) {
  const TriangleCase& c = GetParam();
  const CompiledScene scene(triangle_scene(c.tri, LightSampling::SolidAngle));
  const LightSampler& lights = scene.lights();
  const Triangle t = make_triangle(scene.scene().shapes[0], 0);
  const dvec3 o(c.ref);
  const double omega = spherical_triangle_solid_angle(dvec3(t.p0) - o, dvec3(t.p1) - o, dvec3(t.p2) - o);
  const bool spherical = omega >= kMinSphericalTriangle && omega <= kMaxSphericalTriangle;
  ASSERT_EQ(spherical, c.spherical) << "Omega " << omega;

  const Grid grid{8};
  const std::size_t n_samples = 200000;
  std::vector<double> observed(static_cast<std::size_t>(grid.cells()) + 1, 0.0), expected(observed.size(), 0.0);
  std::size_t none = 0;
  for (std::size_t k = 0; k < n_samples; ++k) {
    const auto ls = lights.sample(c.ref, uniform(1, k), vec2(uniform(2, k), uniform(3, k)));
    if (!ls) {
      ++none;
      continue;
    }
    ASSERT_TRUE(std::isfinite(ls->pdf) && ls->pdf > 0.0f);
    if (ls->light != 0) {
      observed.back() += 1.0;
      continue;
    }
    const vec2 b = triangle_barycentrics_along(o, dvec3(ls->wi), dvec3(t.p0), dvec3(t.p1), dvec3(t.p2));
    observed[static_cast<std::size_t>(grid.cell(b.x, b.y))] += 1.0;
    // pdf() of the point sampled: the density sample() used, the same bits
    // on the spherical branch (one computation, one rule), to rounding of
    // the point on the area branch.
    if (k < 2000) {
      Surfel hit;
      hit.shape = 0;
      hit.prim = 0;
      hit.p = ls->p;
      hit.n = ls->n;
      if (spherical) {
        ASSERT_EQ(lights.pdf(c.ref, hit), ls->pdf) << "sample " << k;
      } else {
        ASSERT_NEAR(lights.pdf(c.ref, hit), ls->pdf, 1e-3f * ls->pdf) << "sample " << k;
      }
    }
  }
  EXPECT_EQ(none, 0u);  // two-sided, not in the plane
  double total = 0.0, total_coarse = 0.0;
  grid.for_each([&](int i, int j, bool upper) {
    const double e = integrate_pdf(lights, t, c.ref, grid.corners(i, j, upper), 8, spherical);
    expected[static_cast<std::size_t>(grid.index(i, j, upper))] = e * double(n_samples);
    total += e;
    total_coarse += integrate_pdf(lights, t, c.ref, grid.corners(i, j, upper), 4, spherical);
  });
  // The density integrates to the pick probability over the light (the
  // quadrature's error, estimated by halving, is far below 1e-3).
  const float pick = lights.pmf()[0];
  EXPECT_NEAR(total, pick, 1e-3 * pick) << "coarse " << total_coarse;
  EXPECT_NEAR(total, total_coarse, 1e-4 * pick);
  expected.back() = double(n_samples) * (1.0 - total);
  EXPECT_TRUE(test::chi2_fit(observed, expected, test::sidak(kAlpha, kComparisons))) << c.name << " Omega " << omega;
}

INSTANTIATE_TEST_SUITE_P(Shapes, TriangleChi2, testing::ValuesIn(triangle_cases()),
                         [](const testing::TestParamInfo<TriangleCase>& p) { return p.param.name; });

struct SphereCase {
  std::string name;
  vec3 center;
  float radius;
  vec3 ref;
  bool cone;
};

void PrintTo(const SphereCase& c, std::ostream* os) { *os << c.name; }

std::vector<SphereCase> sphere_cases() {
  return {{"far", vec3(0, 0, 0), 1.0f, vec3(0.0f, 0.0f, 5.0f), true},
          {"near", vec3(0, 0, 0), 1.0f, vec3(0.3f, 0.2f, 1.05f), true},
          {"grazing_surface", vec3(0, 0, 0), 1.0f, vec3(0.0f, 1.001f, 0.0f), true},
          {"very_far", vec3(1, 2, 3), 0.01f, vec3(1.0f, 2.0f, 3.0f + 1e2f), true},
          {"inside", vec3(0, 0, 0), 1.0f, vec3(0.2f, -0.3f, 0.4f), false},
          {"on_surface", vec3(0, 0, 0), 1.0f, vec3(0.0f, 0.0f, 1.0f), false}};
}

class SphereChi2 : public testing::TestWithParam<SphereCase> {};

TEST_P(SphereChi2, DirectionsHaveTheDensityPdfReports) {
  const SphereCase& c = GetParam();
  const CompiledScene scene(sphere_scene(c.center, c.radius, LightSampling::SolidAngle));
  const LightSampler& lights = scene.lights();
  const dvec3 o(c.ref), center(c.center);
  const double r = c.radius;
  const dvec3 to = center - o;
  const bool cone = glm::dot(to, to) > kSphereConeMargin * r * r;
  ASSERT_EQ(cone, c.cone);
  // Bins about the axis towards the centre: 1 - cos theta up to the cone's
  // (or 2, all directions), phi all round.
  const dvec3 axis = glm::normalize(to);
  const SphereCone sc = sphere_cone(o, center, r);
  const double max_omc = cone ? sc.one_minus_cos_max : 2.0;
  dvec3 bs = glm::normalize(glm::cross(axis, std::abs(axis.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0)));
  const dvec3 bt = glm::cross(axis, bs);
  const int nt = 10, np = 10;
  auto bin_of = [&](const dvec3& w) {
    const double cos_t = glm::dot(w, axis);
    const double sin2 = glm::dot(glm::cross(w, axis), glm::cross(w, axis));
    const double omc = cos_t > 0.0 ? sin2 / (1.0 + cos_t) : 1.0 - cos_t;
    double phi = std::atan2(glm::dot(w, bt), glm::dot(w, bs));
    if (phi < 0.0) phi += 2.0 * kPiD;
    const int it = std::min(nt - 1, static_cast<int>(omc / max_omc * nt));
    const int ip = std::min(np - 1, static_cast<int>(phi / (2.0 * kPiD) * np));
    return static_cast<std::size_t>(it * np + ip);
  };
  // The nearest crossing of the sphere along w (every w in the bins has one).
  auto hit_along = [&](const dvec3& w) {
    const double b = glm::dot(w, to), cc = glm::dot(to, to) - r * r;
    const double disc = std::max(0.0, b * b - cc);
    const double t = cc > 0.0 ? cc / (b + std::sqrt(disc)) : b + std::sqrt(disc);
    Surfel hit;
    hit.shape = 0;
    hit.prim = 0;
    const dvec3 p = o + t * w;
    hit.p = vec3(p);
    hit.n = vec3(glm::normalize(p - center));
    return hit;
  };
  const std::size_t n_samples = 200000;
  std::vector<double> observed(static_cast<std::size_t>(nt * np) + 1, 0.0), expected(observed.size(), 0.0);
  for (std::size_t k = 0; k < n_samples; ++k) {
    const auto ls = lights.sample(c.ref, uniform(11, k), vec2(uniform(12, k), uniform(13, k)));
    if (!ls) continue;  // a point seen edge-on (the area branch, on the surface)
    ASSERT_TRUE(std::isfinite(ls->pdf) && ls->pdf > 0.0f);
    if (ls->light != 0) {
      observed.back() += 1.0;
      continue;
    }
    observed[bin_of(dvec3(ls->wi))] += 1.0;
    if (cone && k < 2000) {
      ASSERT_EQ(lights.pdf(c.ref, hit_along(dvec3(ls->wi))), ls->pdf) << "sample " << k;
    }
  }
  // Each bin by a 16 x 16 midpoint rule in (1 - cos theta, phi).
  const int m = 16;
  double total = 0.0;
  for (int it = 0; it < nt; ++it)
    for (int ip = 0; ip < np; ++ip) {
      double e = 0.0;
      for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b) {
          const double omc = max_omc * (it + (a + 0.5) / m) / nt, phi = 2.0 * kPiD * (ip + (b + 0.5) / m) / np;
          const double cos_t = 1.0 - omc, sin_t = std::sqrt(std::max(0.0, omc * (2.0 - omc)));
          const dvec3 w = sin_t * (std::cos(phi) * bs + std::sin(phi) * bt) + cos_t * axis;
          e += double(lights.pdf(c.ref, hit_along(w)));
        }
      e *= 2.0 * kPiD * max_omc / (double(nt) * np * m * m);
      expected[static_cast<std::size_t>(it * np + ip)] = e * double(n_samples);
      total += e;
    }
  const float pick = lights.pmf()[0];
  EXPECT_NEAR(total, pick, (cone ? 1e-4 : 2e-2) * pick);  // exact for the cone's constant density
  expected.back() = double(n_samples) * (1.0 - total);
  EXPECT_TRUE(test::chi2_fit(observed, expected, test::sidak(kAlpha, kComparisons))) << c.name;
}

INSTANTIATE_TEST_SUITE_P(Places, SphereChi2, testing::ValuesIn(sphere_cases()),
                         [](const testing::TestParamInfo<SphereCase>& p) { return p.param.name; });

// Van Oosterom & Strackee against exact values: an octant (pi / 2), half a
// cube face seen from the centre (4 pi / 12), and Girard's theorem (angle
// excess, long double) on random triangles large enough for it to be accurate.
TEST(SolidAngle, TriangleSolidAngleMatchesClosedForms) {
  EXPECT_NEAR(spherical_triangle_solid_angle({1, 0, 0}, {0, 1, 0}, {0, 0, 1}), kPiD / 2.0, 1e-15);
  EXPECT_NEAR(spherical_triangle_solid_angle({3, 0, 0}, {0, 0.5, 0}, {0, 0, 7}), kPiD / 2.0, 1e-15);
  EXPECT_NEAR(spherical_triangle_solid_angle({-1, -1, 1}, {1, -1, 1}, {1, 1, 1}), 4.0 * kPiD / 12.0, 1e-15);
  EXPECT_EQ(spherical_triangle_solid_angle({0, 0, 1}, {1, 0, 1}, {2, 0, 1}), 0.0);   // degenerate
  EXPECT_EQ(spherical_triangle_solid_angle({1, 0, 0}, {2, 1, 0}, {2, -1, 0}), 0.0);  // the origin in the plane, outside
  EXPECT_NEAR(spherical_triangle_solid_angle({-1, -1, 0}, {1, -1, 0}, {0, 1, 0}), 2.0 * kPiD, 1e-15);  // inside
  auto girard = [](dvec3 a, dvec3 b, dvec3 c) {
    using ld = long double;
    a = glm::normalize(a), b = glm::normalize(b), c = glm::normalize(c);
    auto angle = [](const dvec3& x, const dvec3& y, const dvec3& z) {
      const dvec3 ty = y - glm::dot(x, y) * x, tz = z - glm::dot(x, z) * x;
      return std::atan2(static_cast<ld>(glm::length(glm::cross(ty, tz))), static_cast<ld>(glm::dot(ty, tz)));
    };
    return static_cast<double>(angle(a, b, c) + angle(b, c, a) + angle(c, a, b) - std::numbers::pi_v<ld>);
  };
  for (std::uint64_t k = 0; k < 1000; ++k) {
    dvec3 v[3];
    for (int i = 0; i < 3; ++i)
      v[i] = dvec3(uniform(20 + i, k), uniform(30 + i, k), uniform(40 + i, k)) * 2.0 - 1.0;
    const double g = girard(v[0], v[1], v[2]);
    if (g < 1e-3) continue;  // Girard cancels catastrophically for small triangles
    EXPECT_NEAR(spherical_triangle_solid_angle(v[0], v[1], v[2]), g, 1e-12) << k;
  }
}

// Irradiance at a point from a light of radiance 1, estimated by next-event
// samples, against the closed form; and the variance of solid-angle
// sampling below area sampling's at a point near the light.
struct Estimate {
  double mean = 0.0, variance = 0.0;
};
// `sphere`: the light is a sphere, whose far side it hides itself (the
// shadow ray a tracer casts would hit its near side): a point counts only if
// it faces x.
Estimate irradiance(const LightSampler& lights, const vec3& x, const vec3& n, std::uint64_t seed, std::size_t count,
                    bool sphere = false) {
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    double v = 0.0;
    const auto ls = lights.sample(x, uniform(seed, k), vec2(uniform(seed + 1, k), uniform(seed + 2, k)));
    const bool visible = ls && (!sphere || glm::dot(ls->n, ls->wi) < 0.0f);
    if (visible && ls->light == 0) v = double(ls->Le.x) * std::max(0.0, double(glm::dot(n, ls->wi))) / double(ls->pdf);
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / double(count);
  return {mean, (sum2 / double(count) - mean * mean)};
}

// z of an estimate against the truth, from its own variance.
double z_of(const Estimate& e, double truth, std::size_t count) {
  return (e.mean - truth) / std::sqrt(std::max(e.variance, 1e-300) / double(count));
}

TEST(SolidAngle, TriangleIrradianceMatchesLambertAndBeatsAreaNearby) {
  const std::array<vec3, 3> tri{vec3(-1, -1, 0), vec3(1, -1, 0), vec3(0, 1, 0)};
  struct Point {
    vec3 x, n;
    bool near;
  };
  const Point points[] = {{vec3(0.1f, -0.2f, 0.1f), vec3(0, 0, -1), true},
                          {vec3(0.3f, 0.1f, 1.5f), glm::normalize(vec3(0.3f, 0.0f, -1.0f)), false},
                          {vec3(1.2f, 0.0f, 0.3f), glm::normalize(vec3(-1.0f, 0.2f, -0.5f)), true},
                          {vec3(0.0f, -1.3f, -0.2f), glm::normalize(vec3(0.1f, 1.0f, 0.4f)), false}};
  const std::size_t count = 100000;
  const double z = test::sidak_z(kAlpha, kComparisons);
  const CompiledScene area(triangle_scene(tri, LightSampling::Area)), solid(triangle_scene(tri, LightSampling::SolidAngle));
  for (const Point& p : points) {
    const std::array<dvec3, 3> poly{dvec3(tri[0]), dvec3(tri[1]), dvec3(tri[2])};
    const double truth = analytic::polygon_form_factor(poly, dvec3(p.x), dvec3(p.n));
    const Estimate a = irradiance(area.lights(), p.x, p.n, 100, count), s = irradiance(solid.lights(), p.x, p.n, 200, count);
    EXPECT_LT(std::abs(z_of(s, truth, count)), z) << "solid angle: " << s.mean << " vs " << truth;
    EXPECT_LT(std::abs(z_of(a, truth, count)), z) << "area: " << a.mean << " vs " << truth;
    RecordProperty("variance_ratio_" + std::to_string(&p - points), std::to_string(s.variance / a.variance));
    if (p.near) {
      EXPECT_LT(s.variance, a.variance) << "at (" << p.x.x << ", " << p.x.y << ", " << p.x.z << ")";
    }
  }
}

// A sphere of radius r at distance d fully above the horizon of a point
// whose normal makes angle theta with the direction to its centre:
// E = pi L sin^2(alpha) cos(theta), sin alpha = r / d.
TEST(SolidAngle, SphereIrradianceMatchesClosedFormAndBeatsAreaNearby) {
  struct Place {
    float d, theta;
    bool near;
  };
  const Place places[] = {{1.2f, 0.0f, true}, {1.5f, 0.5f, true}, {6.0f, 0.2f, false}};
  const std::size_t count = 100000;
  const double z = test::sidak_z(kAlpha, kComparisons);
  const CompiledScene area(sphere_scene(vec3(0.0f), 1.0f, LightSampling::Area)),
      solid(sphere_scene(vec3(0.0f), 1.0f, LightSampling::SolidAngle));
  for (const Place& p : places) {
    const vec3 x(0.0f, 0.0f, p.d);
    const vec3 n(std::sin(p.theta), 0.0f, -std::cos(p.theta));
    const double sin2 = 1.0 / (double(p.d) * p.d);
    ASSERT_LE(std::asin(std::sqrt(sin2)) + p.theta, kPiD / 2.0);
    const double truth = kPiD * sin2 * std::cos(double(p.theta));
    const Estimate a = irradiance(area.lights(), x, n, 300, count, true),
                   s = irradiance(solid.lights(), x, n, 400, count, true);
    EXPECT_LT(std::abs(z_of(s, truth, count)), z) << "solid angle: " << s.mean << " vs " << truth;
    EXPECT_LT(std::abs(z_of(a, truth, count)), z) << "area: " << a.mean << " vs " << truth;
    if (p.near) {
      EXPECT_LT(s.variance, a.variance) << "d " << p.d;
    }
  }
}

// Extremes: tiny and distant triangles, a point in the light's plane, a
// degenerate triangle, a point at a vertex: finite samples and densities or
// none, never NaN; sample() and pdf() agree on each.
TEST(SolidAngle, ExtremesGiveFiniteResultsOrNone) {
  struct Extreme {
    const char* name;
    std::array<vec3, 3> tri;
    vec3 ref;
  };
  const std::array<vec3, 3> unit{vec3(-1, -1, 0), vec3(1, -1, 0), vec3(0, 1, 0)};
  const Extreme cases[] = {
      {"tiny 1e-6", {vec3(0, 0, 0), vec3(1e-6f, 0, 0), vec3(0, 1e-6f, 0)}, vec3(0.0f, 0.0f, 1.0f)},
      {"tiny 1e-6 at 1e-6", {vec3(0, 0, 0), vec3(1e-6f, 0, 0), vec3(0, 1e-6f, 0)}, vec3(2e-7f, 2e-7f, 1e-6f)},
      {"distant 1e6", unit, vec3(0.0f, 0.0f, 1e6f)},
      {"huge at 1e6", {vec3(-1e6f, -1e6f, 0), vec3(1e6f, -1e6f, 0), vec3(0, 1e6f, 0)}, vec3(0.0f, 0.0f, 1.0f)},
      {"in the plane, outside", unit, vec3(3.0f, 0.0f, 0.0f)},
      {"in the plane, inside", unit, vec3(0.0f, -0.2f, 0.0f)},
      {"1e-6 above the plane", unit, vec3(0.0f, -0.2f, 1e-6f)},
      {"at a vertex", unit, vec3(1.0f, -1.0f, 0.0f)},
      {"degenerate (collinear)", {vec3(0, 0, 0), vec3(1, 0, 0), vec3(2, 0, 0)}, vec3(0.5f, 0.5f, 0.5f)},
      {"degenerate (a point)", {vec3(1, 1, 1), vec3(1, 1, 1), vec3(1, 1, 1)}, vec3(0.5f, 0.5f, 0.5f)},
  };
  for (const Extreme& e : cases) {
    const CompiledScene scene(triangle_scene(e.tri, LightSampling::SolidAngle));
    const LightSampler& lights = scene.lights();
    std::size_t disagree = 0;
    for (std::uint64_t k = 0; k < 2000; ++k) {
      const auto ls = lights.sample(e.ref, uniform(50, k) * lights.cdf()[0], vec2(uniform(51, k), uniform(52, k)));
      if (!ls) continue;
      ASSERT_TRUE(std::isfinite(ls->pdf) && ls->pdf > 0.0f) << e.name;
      ASSERT_TRUE(is_finite(ls->p) && is_finite(ls->wi) && std::isfinite(ls->dist)) << e.name;
      if (ls->light != 0) continue;  // the other light (a degenerate one is never picked)
      Surfel hit;
      hit.shape = 0;
      hit.prim = 0;
      hit.p = ls->p;
      hit.n = ls->n;
      const float pdf = lights.pdf(e.ref, hit);
      ASSERT_TRUE(std::isfinite(pdf)) << e.name;
      // The same (ref, light): the same branch, so the same density (the
      // area branch recomputes it from the point, to rounding).
      if (!(std::abs(pdf - ls->pdf) <= 1e-3f * ls->pdf)) ++disagree;
    }
    EXPECT_EQ(disagree, 0u) << e.name << ": pdf() differs from the sample's density";
    Surfel hit;
    hit.shape = 0;
    hit.prim = 0;
    hit.p = (e.tri[0] + e.tri[1] + e.tri[2]) / 3.0f;
    hit.n = vec3(0, 0, 1);
    EXPECT_FALSE(std::isnan(lights.pdf(e.ref, hit))) << e.name;
  }
  // The pure functions on degenerate input.
  EXPECT_EQ(spherical_triangle_solid_angle(dvec3(0.0), dvec3(0.0), dvec3(0.0)), 0.0);
  const vec2 b = triangle_barycentrics_along(dvec3(0, 0, 1), dvec3(1, 0, 0), dvec3(0.0), dvec3(1, 0, 0), dvec3(0, 1, 0));
  EXPECT_TRUE(std::isfinite(b.x) && std::isfinite(b.y));
}

// The default is area sampling, and solid_angle changes what is sampled
// (not a no-op): on a near point the two give different directions.
TEST(SolidAngle, AreaIsTheDefaultAndSolidAngleDiffers) {
  EXPECT_EQ(RenderSettings{}.light_sampling, LightSampling::Area);
  const std::array<vec3, 3> tri{vec3(-1, -1, 0), vec3(1, -1, 0), vec3(0, 1, 0)};
  const CompiledScene area(triangle_scene(tri, LightSampling::Area)), solid(triangle_scene(tri, LightSampling::SolidAngle));
  EXPECT_EQ(area.lights().light_sampling(), LightSampling::Area);
  EXPECT_EQ(solid.lights().light_sampling(), LightSampling::SolidAngle);
  const auto a = area.lights().sample(vec3(0.0f, 0.0f, 0.3f), 0.1f, vec2(0.3f, 0.6f));
  const auto s = solid.lights().sample(vec3(0.0f, 0.0f, 0.3f), 0.1f, vec2(0.3f, 0.6f));
  ASSERT_TRUE(a && s);
  EXPECT_NE(a->wi, s->wi);
}

}  // namespace
}  // namespace pathlab
