// The light BVH (render.light_sampler: bvh; core/light_bvh.h): the
// probability pdf() multiplies by is the probability with which the tree
// really picks each light (chi-square at several shading points, lights
// behind the point never picked), it follows the importance formula
// (closed form for two and three lights), degenerate bounds stay finite, and
// both tracers stay unbiased (analytic checks) under bvh and bvh x
// solid_angle.
#include "tests/check_util.h"
#include "tests/stat_util.h"
#include "tests/test_scenes.h"

#include "core/compiled_scene.h"
#include "core/light_bvh.h"
#include "core/rng.h"
#include "wavefront/wavefront_tracer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numeric>

namespace pathlab {
namespace {

using test::add_light_triangle;

void add_light_sphere(Scene& scene, const vec3& c, float r, float Le) {
  scene.materials.push_back(Material{"ball" + std::to_string(scene.materials.size()), MaterialType::Emissive,
                                     Spectrum(0.0f), Spectrum(Le), false});
  Shape s;
  s.description = "shapes[" + std::to_string(scene.shapes.size()) + "] (light sphere)";
  s.kind = Shape::Kind::Sphere;
  s.center = c;
  s.radius = r;
  s.material = static_cast<std::uint32_t>(scene.materials.size() - 1);
  scene.shapes.push_back(std::move(s));
}

Scene bvh_scene() {
  Scene scene;
  scene.name = "light-bvh";
  scene.render.light_sampler = LightSamplerKind::Bvh;
  return scene;
}

// Lights of unequal power and orientation: a 4 x 4 grid facing down at
// height 2 (every fifth two-sided), two upright ones facing +x and -x, one
// facing up above the grid, a sphere, and two coincident triangles.
Scene many_lights() {
  Scene scene = bvh_scene();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const vec3 c(-1.5f + float(i), -1.5f + float(j), 2.0f);
      const float Le = 1.0f + float((7 * i + 3 * j) % 5) * 2.0f;
      add_light_triangle(scene, c, c + vec3(0.0f, 0.3f, 0.0f), c + vec3(0.3f, 0.0f, 0.0f), Le, (4 * i + j) % 5 == 0);
    }
  add_light_triangle(scene, vec3(3, 0, 0.5f), vec3(3, 0.5f, 0.5f), vec3(3, 0, 1), 4.0f);    // facing +x
  add_light_triangle(scene, vec3(-3, 0, 0.5f), vec3(-3, 0, 1), vec3(-3, 0.5f, 0.5f), 6.0f);  // facing -x
  add_light_triangle(scene, vec3(0, 0, 2.5f), vec3(0.4f, 0, 2.5f), vec3(0, 0.4f, 2.5f), 3.0f);  // facing up
  add_light_sphere(scene, vec3(2.0f, -2.0f, 1.0f), 0.2f, 2.0f);
  for (int twice = 0; twice < 2; ++twice)
    add_light_triangle(scene, vec3(-2, 2, 1.5f), vec3(-2, 2.2f, 1.5f), vec3(-1.8f, 2, 1.5f), 5.0f);
  return scene;
}

struct Place {
  const char* name;
  LightQuery q;
  bool complete;  // every grid point leads to a light: the pmfs sum to 1
};

const Place kPlaces[] = {
    {"below, facing up", {vec3(0.1f, 0.2f, 0.0f), vec3(0, 0, 1)}, true},
    {"below, facing down: every light behind", {vec3(0.1f, 0.2f, 0.0f), vec3(0, 0, -1)}, false},
    {"above, facing down: one-sided backs", {vec3(0.3f, -0.4f, 4.0f), vec3(0, 0, -1)}, false},
    {"among the grid, facing up", {vec3(0.35f, 0.3f, 2.0f), vec3(0, 0, 1)}, false},
    {"a bare point beside", {vec3(2.5f, 1.0f, 1.0f), vec3(0.0f)}, false},
    {"on a wall, facing +x", {vec3(-2.9f, 0.1f, 0.7f), vec3(1, 0, 0)}, false},
    {"inside the sphere light", {vec3(2.05f, -2.0f, 1.0f), vec3(0, 1, 0)}, false},
};

float u_of(std::uint64_t seed, std::uint64_t k) { return to_unit_float(mix64(seed * 0x9e3779b97f4a7c15ull + k)); }

// At each place: the pmfs are finite, sum to at most 1 (exactly 1 where the
// walk cannot die), and are the frequencies with which pick() chooses each
// light (chi-square over lights plus "none", Sidak over the places); a light
// of pmf 0 is never picked. sample()'s density and pdf() at the sampled
// point agree.
TEST(LightBvh, PmfIsThePickFrequency) {
  const CompiledScene compiled(many_lights());
  const LightSampler& lights = compiled.lights();
  ASSERT_EQ(lights.light_sampler(), LightSamplerKind::Bvh);
  ASSERT_NE(lights.bvh(), nullptr);
  const std::size_t n = lights.entries().size();
  const double alpha = test::sidak(0.01, static_cast<double>(std::size(kPlaces)));
  const std::uint64_t samples = 200000 * static_cast<std::uint64_t>(test::stat_scale());
  for (const Place& place : kPlaces) {
    std::vector<double> pmf(n + 1, 0.0);
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      pmf[i] = lights.pick_pmf(place.q, i);
      ASSERT_TRUE(std::isfinite(pmf[i]) && pmf[i] >= 0.0) << place.name;
      sum += pmf[i];
    }
    EXPECT_LE(sum, 1.0) << place.name;
    if (place.complete) {
      EXPECT_EQ(sum, 1.0) << place.name;
    }
    pmf[n] = std::max(0.0, 1.0 - sum);  // the walk ended with no light
    std::vector<double> observed(n + 1, 0.0), expected(n + 1, 0.0);
    std::size_t disagree = 0, checked = 0, pick_differs = 0;
    for (std::uint64_t k = 0; k < samples; ++k) {
      const float u = u_of(1, k);
      const auto p = lights.pick(place.q, u);
      const std::size_t cell = p ? p->entry : n;
      observed[cell] += 1.0;
      if (p) {
        ASSERT_GT(p->pmf, 0.0f) << place.name << ": picked entry " << p->entry << " with pmf 0";
        if (p->pmf != lights.pick_pmf(place.q, p->entry)) ++pick_differs;
      }
      if (k < 4000) {
        const auto ls = lights.sample(place.q, u, vec2(u_of(2, k), u_of(3, k)));
        if (!ls) continue;
        Surfel hit;
        hit.p = ls->p;
        hit.n = ls->n;
        hit.shape = lights.entries()[ls->light].shape;
        hit.prim = lights.entries()[ls->light].prim;
        const float pdf = lights.pdf(place.q, hit);
        ++checked;
        if (!(std::abs(pdf - ls->pdf) <= 1e-3f * ls->pdf)) ++disagree;
      }
    }
    EXPECT_EQ(pick_differs, 0u) << place.name << ": the probability pick() reports is not pick_pmf()'s";
    EXPECT_EQ(disagree, 0u) << place.name << ": pdf() differs from the density of " << disagree << " of " << checked
                            << " samples";
    for (std::size_t i = 0; i <= n; ++i) {
      expected[i] = pmf[i] * static_cast<double>(samples);
      if (pmf[i] == 0.0) {
        EXPECT_EQ(observed[i], 0.0) << place.name << ": cell " << i << " has pmf 0";
      }
    }
    if (std::accumulate(expected.begin(), expected.end(), 0.0) - expected[n] > 0.0) {
      EXPECT_TRUE(test::chi2_fit(observed, expected, alpha)) << place.name;
    }
  }
}

// The places where the answer is known: every light behind the surface
// gives nothing at all; from above, facing down, the one-sided lights of
// the grid show their backs (pmf 0) and the two-sided ones and the one facing
// up do not.
TEST(LightBvh, LightsBehindTheSurfaceOrFacingAwayAreNeverPicked) {
  const CompiledScene compiled(many_lights());
  const LightSampler& lights = compiled.lights();
  const Scene& scene = compiled.scene();
  const LightQuery behind = kPlaces[1].q, above = kPlaces[2].q;
  for (std::size_t i = 0; i < lights.entries().size(); ++i) EXPECT_EQ(lights.pick_pmf(behind, i), 0.0f) << i;
  for (std::uint64_t k = 0; k < 1000; ++k) EXPECT_FALSE(lights.pick(behind, u_of(4, k)).has_value());
  for (std::size_t i = 0; i < 16; ++i) {
    const bool two_sided = scene.materials[scene.shapes[lights.entries()[i].shape].material].two_sided_emission;
    if (two_sided) {
      EXPECT_GT(lights.pick_pmf(above, i), 0.0f) << i;
    } else {
      EXPECT_EQ(lights.pick_pmf(above, i), 0.0f) << i;
    }
  }
  EXPECT_GT(lights.pick_pmf(above, 18), 0.0f);  // facing up
}

// The importance formula, written here with angles (the implementation
// subtracts cosines): a node of bounds [lo, hi], power phi and one normal n
// (theta_o = 0) at shading point q.
double importance_by_hand(const dvec3& lo, const dvec3& hi, const dvec3& n, double phi, const LightQuery& q) {
  const dvec3 c = 0.5 * (lo + hi);
  const double r2 = glm::dot(hi - lo, hi - lo) / 4.0;
  const dvec3 d = dvec3(q.p) - c;
  const double d2 = glm::dot(d, d);
  const double theta_b = std::asin(std::sqrt(r2 / d2));
  const double theta = std::max(0.0, std::acos(glm::dot(n, d / std::sqrt(d2))) - theta_b);
  if (theta >= std::acos(-1.0) / 2.0) return 0.0;
  const double theta_ip = std::max(0.0, std::acos(glm::dot(dvec3(q.n), -d / std::sqrt(d2))) - theta_b);
  if (theta_ip >= std::acos(-1.0) / 2.0) return 0.0;
  return phi * std::cos(theta) * std::cos(theta_ip) / std::max(d2, r2 / 4.0);
}
dvec3 box_lo(const std::array<vec3, 3>& t) { return glm::min(dvec3(t[0]), glm::min(dvec3(t[1]), dvec3(t[2]))); }
dvec3 box_hi(const std::array<vec3, 3>& t) { return glm::max(dvec3(t[0]), glm::max(dvec3(t[1]), dvec3(t[2]))); }
dvec3 normal_of(const std::array<vec3, 3>& t) { return glm::normalize(glm::cross(dvec3(t[1] - t[0]), dvec3(t[2] - t[0]))); }

// One triangle's node.
double importance_by_hand(const std::array<vec3, 3>& t, double phi, const LightQuery& q) {
  return importance_by_hand(box_lo(t), box_hi(t), normal_of(t), phi, q);
}

// A node holding two triangles of one normal (their box, theta_o = 0).
double importance_of_pair(const std::array<vec3, 3>& a, const std::array<vec3, 3>& b, double phi,
                          const LightQuery& q) {
  return importance_by_hand(glm::min(box_lo(a), box_lo(b)), glm::max(box_hi(a), box_hi(b)), normal_of(a), phi, q);
}

double power_of(const std::array<vec3, 3>& t, float Le) {
  // pi * Y(L) * area; add_light_triangle's radiance is (Le, 0.8 Le, 0.6 Le).
  const double area = 0.5 * glm::length(glm::cross(dvec3(t[1] - t[0]), dvec3(t[2] - t[0])));
  return std::acos(-1.0) * luminance_double(Spectrum(Le, 0.8f * Le, 0.6f * Le)) * area;
}

// Two lights: the tree's root has them as children, so each is picked with
// probability I / (I_a + I_b), to the grid's 2^-24. Three: a and b close
// together, c far, so the root splits {a, b} | {c}.
TEST(LightBvh, PmfFollowsTheImportanceFormula) {
  const std::array<vec3, 3> a{vec3(0, 0, 2), vec3(0.5f, 0, 2), vec3(0, 0.5f, 2)};      // facing up
  const std::array<vec3, 3> b{vec3(1, 0, 2), vec3(1, 0.4f, 2), vec3(1.4f, 0, 2)};      // facing down
  const std::array<vec3, 3> a2{vec3(0.6f, 0, 2), vec3(0.9f, 0, 2), vec3(0.6f, 0.3f, 2)};  // beside a, facing up
  const std::array<vec3, 3> c{vec3(6, 0, 0), vec3(6, 0, 0.5f), vec3(6, 0.5f, 0)};      // far, facing -x (them)
  constexpr double kGrid = 0x1p-24;
  const LightQuery places[] = {{vec3(0.3f, 0.1f, 0.0f), vec3(0, 0, 1)},
                               {vec3(2.0f, 1.0f, 3.0f), glm::normalize(vec3(-1, 0, -1))},
                               {vec3(0.2f, 0.2f, 2.5f), vec3(0, 0, 1)}};
  {
    Scene scene = bvh_scene();
    add_light_triangle(scene, a[0], a[1], a[2], 3.0f);
    add_light_triangle(scene, b[0], b[1], b[2], 1.0f);
    const CompiledScene compiled(std::move(scene));
    for (const LightQuery& q : places) {
      const double ia = importance_by_hand(a, power_of(a, 3.0f), q), ib = importance_by_hand(b, power_of(b, 1.0f), q);
      const double pa = ia + ib > 0.0 ? ia / (ia + ib) : 0.0;
      EXPECT_NEAR(compiled.lights().pick_pmf(q, 0), pa, kGrid) << q.p.x << " " << q.p.z;
      EXPECT_NEAR(compiled.lights().pick_pmf(q, 1), ia + ib > 0.0 ? 1.0 - pa : 0.0, kGrid);
    }
  }
  {
    Scene scene = bvh_scene();
    add_light_triangle(scene, a[0], a[1], a[2], 3.0f);
    add_light_triangle(scene, a2[0], a2[1], a2[2], 5.0f);
    add_light_triangle(scene, c[0], c[1], c[2], 40.0f);
    const CompiledScene compiled(std::move(scene));
    ASSERT_EQ(compiled.lights().bvh()->node_count(), 5u);
    for (const LightQuery& q : places) {
      const double phi_a = power_of(a, 3.0f), phi_a2 = power_of(a2, 5.0f);
      const double ia = importance_by_hand(a, phi_a, q), ia2 = importance_by_hand(a2, phi_a2, q);
      const double ic = importance_by_hand(c, power_of(c, 40.0f), q);
      const double ipair = importance_of_pair(a, a2, phi_a + phi_a2, q);
      const double p_pair = ipair + ic > 0.0 ? ipair / (ipair + ic) : 0.0;
      const double pa = ia + ia2 > 0.0 ? p_pair * ia / (ia + ia2) : 0.0;
      const double pa2 = ia + ia2 > 0.0 ? p_pair * ia2 / (ia + ia2) : 0.0;
      const double pc = ipair + ic > 0.0 ? 1.0 - p_pair : 0.0;
      EXPECT_NEAR(compiled.lights().pick_pmf(q, 0), pa, 2 * kGrid) << q.p.x << " " << q.p.z;
      EXPECT_NEAR(compiled.lights().pick_pmf(q, 1), pa2, 2 * kGrid) << q.p.x << " " << q.p.z;
      EXPECT_NEAR(compiled.lights().pick_pmf(q, 2), pc, kGrid) << q.p.x << " " << q.p.z;
    }
  }
}

// Degenerate input: one light, coincident lights, a zero-area light (no
// power: outside the tree, never picked, pdf 0), a point at a box's centre
// and inside a sphere light (whole-sphere cone). Finite pmfs that pick()
// and pick_pmf() agree on.
TEST(LightBvh, DegenerateBoundsStayFinite) {
  Scene scene = bvh_scene();
  add_light_triangle(scene, vec3(0, 0, 1), vec3(1, 0, 1), vec3(0, 1, 1), 2.0f);
  add_light_triangle(scene, vec3(0, 0, 1), vec3(1, 0, 1), vec3(0, 1, 1), 2.0f);  // coincident
  add_light_triangle(scene, vec3(3, 0, 1), vec3(4, 0, 1), vec3(5, 0, 1), 2.0f);  // zero area
  add_light_sphere(scene, vec3(0, 0, -3), 0.5f, 1.0f);
  const CompiledScene compiled(std::move(scene));
  const LightSampler& lights = compiled.lights();
  const LightQuery places[] = {{vec3(0.25f, 0.25f, 1.0f), vec3(0, 0, -1)},  // on the triangles' plane, below them
                               {vec3(0.5f, 0.5f, 1.0f), vec3(0.0f)},        // at their box's centre
                               {vec3(0.0f, 0.0f, -3.0f), vec3(0, 0, 1)},    // at the sphere's centre
                               {vec3(0.3f, 0.3f, 0.0f), vec3(0, 0, 1)}};
  for (const LightQuery& q : places) {
    double sum = 0.0;
    for (std::size_t i = 0; i < lights.entries().size(); ++i) {
      const float p = lights.pick_pmf(q, i);
      ASSERT_TRUE(std::isfinite(p) && p >= 0.0f);
      sum += p;
    }
    EXPECT_LE(sum, 1.0);
    EXPECT_EQ(lights.pick_pmf(q, 2), 0.0f);
    EXPECT_EQ(lights.pick_pmf(q, 0), lights.pick_pmf(q, 1));  // coincident: the same importance
    for (std::uint64_t k = 0; k < 2000; ++k) {
      const auto p = lights.pick(q, u_of(5, k));
      if (!p) continue;
      ASSERT_NE(p->entry, 2u);
      ASSERT_EQ(p->pmf, lights.pick_pmf(q, p->entry));
    }
  }
  EXPECT_EQ(lights.unsampled_light_count(), 1u);  // the zero-area triangle
  // A single light: pmf 1 where it can light the point, 0 behind.
  Scene one = bvh_scene();
  add_light_triangle(one, vec3(0, 0, 1), vec3(0, 1, 1), vec3(1, 0, 1), 2.0f);  // facing down
  const CompiledScene single(std::move(one));
  EXPECT_EQ(single.lights().pick_pmf({vec3(0.2f, 0.2f, 0.0f), vec3(0, 0, 1)}, 0), 1.0f);
  EXPECT_EQ(single.lights().pick_pmf({vec3(0.2f, 0.2f, 2.0f), vec3(0, 0, -1)}, 0), 0.0f);
  // The split itself: infinities and zeros.
  EXPECT_EQ(LightBvh::split(0.0, 0.0, 100), std::nullopt);
  EXPECT_EQ(LightBvh::split(std::nan(""), 0.0, 100), std::nullopt);
  EXPECT_EQ(LightBvh::split(1.0, 0.0, 100), 100u);
  EXPECT_EQ(LightBvh::split(0.0, 1.0, 100), 0u);
  EXPECT_EQ(LightBvh::split(1e308, 1e308, 100), 50u);
  EXPECT_EQ(LightBvh::split(3.0, 1.0, 1u << 24), 3u << 22);
}

// The environment and the sun disks stay outside the tree with the fixed
// probability 1 / (count + 1) each, so the sky's pdf needs no shading point.
TEST(LightBvh, TheSkyHasAFixedShare) {
  Scene scene = many_lights();
  scene.environment = Spectrum(0.5f);
  DeltaLight sun{vec3(0.0f), Spectrum(3.0f)};
  sun.kind = DeltaLight::Kind::Directional;
  sun.direction = glm::normalize(vec3(0.2f, -0.3f, -1.0f));
  sun.angular_radius = 0.05f;
  scene.delta_lights.push_back(sun);
  const CompiledScene compiled(std::move(scene));
  const LightSampler& lights = compiled.lights();
  const std::size_t n = lights.entries().size();
  const float third = static_cast<float>((std::uint32_t{2} << 24) / 3 - (std::uint32_t{1} << 24) / 3) * 0x1p-24f;
  for (const Place& place : kPlaces) {
    EXPECT_EQ(lights.pick_pmf(place.q, n - 2), third) << place.name;  // the environment
    EXPECT_NEAR(lights.pick_pmf(place.q, n - 1), 1.0 / 3.0, 1e-7) << place.name;  // the sun
  }
}

// Unbiasedness: analytic scenes with several lights (furnace-box: twelve
// triangles facing every way, lighting each other), a sphere light seen from
// inside, a textured emitter, a sun and an environment image, a penumbra;
// both tracers, the light-sampling strategies; and under solid_angle too.
struct Case {
  std::string scene;
  Strategy strategy;
  bool wavefront;
  LightSampling light_sampling;
};

class AnalyticUnderBvh : public testing::TestWithParam<Case> {};

TEST_P(AnalyticUnderBvh, PassCheck) {
  Scene scene = test::load_with_strategy(GetParam().scene, GetParam().strategy);
  scene.render.light_sampler = LightSamplerKind::Bvh;
  scene.render.light_sampling = GetParam().light_sampling;
  const CheckResult r = GetParam().wavefront ? test::run_check<WavefrontTracer>(std::move(scene))
                                             : test::run_check(std::move(scene));
  EXPECT_TRUE(r.pixels_pass) << r.failing << " pixel-channels beyond " << r.z_threshold << ", worst z "
                             << r.worst.front().z << " at (" << r.worst.front().x << ", " << r.worst.front().y << ")";
  EXPECT_TRUE(r.bias_pass) << "bias " << r.bias << " +- " << r.bias_se;
}

std::vector<Case> bvh_cases() {
  std::vector<Case> cases;
  for (const char* name : {"furnace-box.json", "penumbra-box.json", "white-sphere-emissive-room.json",
                           "textured-room.json", "envmap-sun-plane.json"})
    for (Strategy s : {Strategy::Light, Strategy::Mis})
      for (bool wavefront : {false, true}) cases.push_back({name, s, wavefront, LightSampling::Area});
  for (bool wavefront : {false, true})
    cases.push_back({"furnace-box.json", Strategy::LightBsdf, wavefront, LightSampling::Area});
  for (const char* name : {"furnace-box.json", "penumbra-box.json", "white-sphere-emissive-room.json"})
    for (bool wavefront : {false, true}) cases.push_back({name, Strategy::Mis, wavefront, LightSampling::SolidAngle});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Bvh, AnalyticUnderBvh, testing::ValuesIn(bvh_cases()),
                         [](const testing::TestParamInfo<Case>& p) {
                           return test::analytic_case_name(p.param.scene, p.param.strategy, p.param.wavefront,
                                                           p.param.light_sampling);
                         });

}  // namespace
}  // namespace pathlab
