// Every discrete choice the renderer makes, as often as the probability it
// reports (label "unit"): the area lights by power, the delta lights by
// power, Distribution1D / Distribution2D cells, the Disney lobe family, the
// dielectric's reflect / refract / absorb and the mirror's absorption.
//
// Each is checked twice:
//  - the reported pmf against its closed form (the weights over their sum,
//    the documented power formulas), to float rounding and the 2^-24 grid of
//    the random numbers;
//  - the frequency of each outcome in N draws of a fixed-seed generator
//    against that reported pmf, by Pearson's chi-square (core of
//    tests/stat_util.h, bins pooled to >= 5 expected), at a per-test level
//    of sidak(1e-3, kTests): the file as a whole fails a correct renderer
//    with probability below 1e-3 (and, the seeds being fixed, never once it
//    has passed).
#include "core/bsdf/disney.h"
#include "core/light_sampler.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "tests/bsdf_checks.h"
#include "tests/stat_util.h"

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <vector>

namespace pathlab {
namespace {

constexpr double kFamilyAlpha = 1e-3;
constexpr int kTests = 8;  // chi-square tests in this file
double alpha() { return test::sidak(kFamilyAlpha, kTests); }

// An emitting triangle in the plane z = 0 facing +z (counter-clockwise seen
// from above), with legs `size` at x = `x`.
Shape emitter_triangle(std::uint32_t material, float x, float size) {
  Shape s;
  s.description = "light";
  s.material = material;
  s.mesh = {{{x, 0, 0}, {x + size, 0, 0}, {x, size, 0}}, {{0, 1, 2}}};
  return s;
}

Material emissive(const char* name, const Spectrum& radiance, bool two_sided) {
  return Material{name, MaterialType::Emissive, Spectrum(0.0f), radiance, two_sided};
}

// Area lights of unequal power: radiance, area and sidedness all differ, one
// is too dim to matter much and one emits from both sides. Closed form
// [light_sampler.h]: power = pi Y(Le) area (x2 two-sided).
TEST(DiscreteChoice, AreaLightsByPowerAsOftenAsThePmfSays) {
  Scene scene;
  scene.name = "area-lights";
  scene.materials = {emissive("a", Spectrum(1.0f, 2.0f, 0.5f), false), emissive("b", Spectrum(4.0f), false),
                     emissive("c", Spectrum(0.3f, 0.1f, 0.9f), true), emissive("d", Spectrum(0.05f), false)};
  const float sizes[4] = {1.0f, 0.5f, 2.0f, 1.5f};
  for (std::uint32_t i = 0; i < 4; ++i) scene.shapes.push_back(emitter_triangle(i, 3.0f * float(i), sizes[i]));
  const LightSampler lights(scene, 10.0f);
  ASSERT_EQ(lights.area_light_count(), 4u);
  double power[4], total = 0.0;
  for (int i = 0; i < 4; ++i) {
    const Spectrum& L = scene.materials[i].emission;
    const double Y = 0.2126 * L.x + 0.7152 * L.y + 0.0722 * L.z;
    power[i] = 3.14159265358979 * Y * 0.5 * sizes[i] * sizes[i] * (scene.materials[i].two_sided_emission ? 2.0 : 1.0);
    total += power[i];
  }
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(lights.pmf()[i], power[i] / total, 2e-7) << "light " << i;
  std::mt19937_64 rng(101);
  const int n = 400000;
  std::vector<double> observed(4, 0.0), expected(4);
  const vec3 ref(3.0f, 1.0f, 5.0f);  // above every light: all face it
  for (int k = 0; k < n; ++k) {
    const float uc = to_unit_float(rng());
    const vec2 u(to_unit_float(rng()), to_unit_float(rng()));
    const auto ls = lights.sample(ref, uc, u);
    ASSERT_TRUE(ls.has_value());
    ASSERT_LT(ls->light, 4u);
    // The pdf divides by the pick probability the pmf reports.
    const float area = 0.5f * sizes[ls->light] * sizes[ls->light];
    const float cos_l = std::abs(ls->wi.z);
    ASSERT_NEAR(ls->pdf, lights.pmf()[ls->light] * ls->dist * ls->dist / (area * cos_l), 1e-4f * ls->pdf);
    observed[ls->light] += 1.0;
  }
  for (int i = 0; i < 4; ++i) expected[i] = n * double(lights.pmf()[i]);
  EXPECT_TRUE(test::chi2_fit(observed, expected, alpha()));
}

// Delta lights of unequal power, two of each kind and a black one (never
// sampled). Closed forms [light_sampler.h]: Y(I) for a point, Y(I) (1 -
// (cos_inner + cos_outer) / 2) / 2 for a spot, Y(E) r^2 / 4 for a
// directional light.
TEST(DiscreteChoice, DeltaLightsByPowerAsOftenAsThePmfSays) {
  Scene scene;
  scene.name = "delta-lights";
  const auto point = [](float i, vec3 p) {
    DeltaLight l;
    l.kind = DeltaLight::Kind::Point;
    l.intensity = Spectrum(i, 0.5f * i, 0.2f * i);
    l.position = p;
    return l;
  };
  DeltaLight spot = point(9.0f, vec3(0, 0, 3));
  spot.kind = DeltaLight::Kind::Spot;
  spot.direction = vec3(0, 0, -1);
  spot.cos_outer = std::cos(0.6f);
  spot.cos_inner = std::cos(0.2f);
  DeltaLight spot2 = spot;
  spot2.cos_outer = std::cos(1.2f);
  spot2.cos_inner = std::cos(1.0f);
  spot2.intensity = Spectrum(2.0f);
  DeltaLight sun;
  sun.kind = DeltaLight::Kind::Directional;
  sun.direction = glm::normalize(vec3(0.2f, 0.1f, -1.0f));
  sun.intensity = Spectrum(0.02f, 0.05f, 0.01f);
  DeltaLight black = point(0.0f, vec3(1, 1, 1));
  scene.delta_lights = {point(1.0f, vec3(0, 0, 2)), black, spot, point(4.0f, vec3(1, 0, 2)), sun, spot2};
  const float radius = 7.0f;
  const LightSampler lights(scene, radius);
  ASSERT_EQ(lights.delta_pmf().size(), 5u);  // the black light is not sampled
  std::vector<double> w;
  const auto Y = [](const Spectrum& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; };
  for (const DeltaLight& l : scene.delta_lights) {
    if (is_black(l.intensity)) continue;
    switch (l.kind) {
      case DeltaLight::Kind::Point: w.push_back(Y(l.intensity)); break;
      case DeltaLight::Kind::Spot:
        w.push_back(0.5 * Y(l.intensity) * (1.0 - 0.5 * (double(l.cos_inner) + double(l.cos_outer))));
        break;
      case DeltaLight::Kind::Directional: w.push_back(0.25 * Y(l.intensity) * radius * radius); break;
    }
  }
  double total = 0.0;
  for (const double x : w) total += x;
  for (std::size_t i = 0; i < w.size(); ++i) EXPECT_NEAR(lights.delta_pmf()[i], w[i] / total, 2e-7) << "light " << i;
  std::mt19937_64 rng(202);
  const int n = 400000;
  std::vector<double> observed(w.size(), 0.0), expected(w.size());
  const vec3 ref(0.0f, 0.0f, 0.0f);  // inside both spots' cones
  for (int k = 0; k < n; ++k) {
    const auto ls = lights.sample_delta(ref, to_unit_float(rng()));
    ASSERT_TRUE(ls.has_value());
    ASSERT_EQ(ls->pdf, lights.delta_pmf()[ls->light]);
    observed[ls->light] += 1.0;
  }
  for (std::size_t i = 0; i < w.size(); ++i) expected[i] = n * double(lights.delta_pmf()[i]);
  EXPECT_TRUE(test::chi2_fit(observed, expected, alpha()));
}

// Distribution1D: pmf(i) = w_i / sum w (zero weights never drawn), the
// density pdf = n pmf, x inside its cell; cells drawn as often as pmf says.
TEST(DiscreteChoice, Distribution1DCellsAsOftenAsThePmfSays) {
  const std::vector<float> weights = {1.0f, 0.0f, 3.0f, 0.5f, 7.0f, 0.0f, 2.5f, 0.01f};
  const Distribution1D d(weights);
  double total = 0.0;
  for (const float x : weights) total += x;
  EXPECT_DOUBLE_EQ(d.total(), total);
  for (std::size_t i = 0; i < weights.size(); ++i) {
    EXPECT_NEAR(d.pmf(i), weights[i] / total, 1e-7) << i;
    EXPECT_FLOAT_EQ(d.pdf(i), d.pmf(i) * float(weights.size())) << i;
  }
  std::mt19937_64 rng(303);
  const int n = 400000;
  std::vector<double> observed(weights.size(), 0.0), expected(weights.size());
  for (int k = 0; k < n; ++k) {
    const Distribution1D::Sample s = d.sample(to_unit_float(rng()));
    ASSERT_LT(s.cell, weights.size());
    ASSERT_GE(s.x * float(weights.size()), float(s.cell));
    ASSERT_LT(s.x * float(weights.size()), float(s.cell + 1));
    ASSERT_EQ(s.pdf, d.pdf(s.cell));
    observed[s.cell] += 1.0;
  }
  for (std::size_t i = 0; i < weights.size(); ++i) expected[i] = n * double(d.pmf(i));
  EXPECT_TRUE(test::chi2_fit(observed, expected, alpha()));
}

// Distribution2D: cell (x, y) with probability w_xy / sum w, density
// pdf(x, y) = W H w_xy / sum w; drawn as often.
TEST(DiscreteChoice, Distribution2DCellsAsOftenAsThePdfSays) {
  const std::size_t W = 5, H = 3;
  const std::vector<float> weights = {1, 2, 0, 4, 1,  //
                                      0, 0, 0, 0, 0,  //
                                      6, 1, 3, 0.2f, 8};
  const Distribution2D d(weights, W, H);
  double total = 0.0;
  for (const float x : weights) total += x;
  for (std::size_t y = 0; y < H; ++y)
    for (std::size_t x = 0; x < W; ++x)
      EXPECT_NEAR(d.pdf(x, y), double(W * H) * weights[y * W + x] / total, 1e-5) << x << "," << y;
  std::mt19937_64 rng(404);
  const int n = 400000;
  std::vector<double> observed(W * H, 0.0), expected(W * H);
  for (int k = 0; k < n; ++k) {
    const vec2 u(to_unit_float(rng()), to_unit_float(rng()));
    const Distribution2D::Sample s = d.sample(u);
    ASSERT_TRUE(s.pdf > 0.0f);
    ASSERT_EQ(s.pdf, d.pdf(s.x, s.y));
    ASSERT_EQ(std::size_t(s.p.x * W), s.x);
    ASSERT_EQ(std::size_t(s.p.y * H), s.y);
    observed[s.y * W + s.x] += 1.0;
  }
  for (std::size_t i = 0; i < W * H; ++i) expected[i] = n * double(d.pdf(i % W, i / W)) / double(W * H);
  EXPECT_TRUE(test::chi2_fit(observed, expected, alpha()));
}

// The Disney lobe family (disney.h): chosen with the probabilities
// lobe_probabilities reports, which are, by its documented heuristic,
//   e = (Y(diffuse) + Y(sheen) / 10,  Y(Cspec0) (1 - Fw) + Fw,  0.25 clearcoat (0.04 + 0.96 Fw)),
//   Fw = (1 - cos_o)^5, normalised, each present lobe floored at 5 %.
TEST(DiscreteChoice, DisneyLobeFamiliesAsOftenAsLobeProbabilitiesSay) {
  DisneyParams p;
  p.base_color = Spectrum(0.7f, 0.4f, 0.2f);
  p.sheen = 0.6f;
  p.metallic = 0.2f;
  p.roughness = 0.3f;
  p.clearcoat = 0.8f;
  const disney::Closure c = disney::make_closure(p);
  int test_index = 0;
  for (const float cos_o : {0.9f, 0.3f}) {
    const vec3 wo = test::bsdf::view_dir(cos_o);
    const disney::LobeProbabilities pr = disney::lobe_probabilities(c, wo, disney::kGeneral, BsdfSampling::Vndf);
    const auto Y = [](const Spectrum& s) { return 0.2126 * s.x + 0.7152 * s.y + 0.0722 * s.z; };
    const double Fw = std::pow(1.0 - cos_o, 5.0);
    const dvec3 diffuse = (1.0 - 0.2) * dvec3(p.base_color);
    const double lum = Y(p.base_color);
    const dvec3 sheen = (1.0 - 0.2) * 0.6 * glm::mix(dvec3(1.0), dvec3(p.base_color) / lum, 0.5);
    const dvec3 spec0 = glm::mix(dvec3(0.5 * 0.08), dvec3(p.base_color), 0.2);
    double e[3] = {Y(Spectrum(diffuse)) + 0.1 * Y(Spectrum(sheen)), Y(Spectrum(spec0)) * (1.0 - Fw) + Fw,
                   0.25 * 0.8 * (0.04 + 0.96 * Fw)};
    const double total = e[0] + e[1] + e[2];
    double q[3], sum = 0.0;
    for (int i = 0; i < 3; ++i) sum += q[i] = std::max(e[i] / total, 0.05);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(pr[i], q[i] / sum, 1e-5) << "family " << i << " at cos " << cos_o;
    // Draw the family; fixed u = (0.5, 0.5) keeps every lobe's direction
    // above the surface, so each draw reports the family it chose.
    std::mt19937_64 rng(505 + test_index++);
    const int n = 200000;
    std::vector<double> observed(3, 0.0), expected(3);
    for (int k = 0; k < n; ++k) {
      const auto ds = disney::sample<disney::kGeneral>(c, wo, to_unit_float(rng()), vec2(0.5f), BsdfSampling::Vndf);
      ASSERT_TRUE(ds.has_value());
      const int family = ds->lobe == Lobe::Specular ? 1 : ds->lobe == Lobe::Clearcoat ? 2 : 0;
      observed[family] += 1.0;
    }
    for (int i = 0; i < 3; ++i) expected[i] = n * double(pr[i]);
    EXPECT_TRUE(test::chi2_fit(observed, expected, alpha())) << "view cos " << cos_o;
  }
}

// The dielectric: reflect with probability F avg(R), refract with
// (1 - F) avg(T), absorbed otherwise (the sample's pdf reports which);
// the mirror: reflect with avg(albedo), absorbed otherwise.
TEST(DiscreteChoice, DielectricAndMirrorImpulsesAsOftenAsTheirProbabilities) {
  const Material glass = dielectric_material({1.7f, Spectrum(0.8f, 0.5f, 0.2f), Spectrum(0.3f, 0.9f, 0.6f)});
  Material mirror;
  mirror.type = MaterialType::Mirror;
  mirror.albedo = Spectrum(0.7f, 0.2f, 0.4f);
  mirror = test::bsdf::configured(mirror, BsdfSampling::Vndf);
  const vec3 wo = test::bsdf::view_dir(0.25f);
  // Fresnel [Born & Wolf 1.5.2], eta 1.7 from outside.
  const double ci = 0.25, eta = 1.7, ct = std::sqrt(1.0 - (1.0 - ci * ci) / (eta * eta));
  const double rs = (ci - eta * ct) / (ci + eta * ct), rp = (eta * ci - ct) / (eta * ci + ct);
  const double F = 0.5 * (rs * rs + rp * rp);
  const double p_glass[3] = {F * 0.5, (1.0 - F) * 0.6, 1.0 - F * 0.5 - (1.0 - F) * 0.6};
  const double p_mirror[3] = {(0.7 + 0.2 + 0.4) / 3.0, 0.0, 1.0 - (0.7 + 0.2 + 0.4) / 3.0};
  for (const bool is_glass : {true, false}) {
    const Surfel s = test::bsdf::flat_surfel(is_glass ? glass : mirror);
    const double* prob = is_glass ? p_glass : p_mirror;
    std::mt19937_64 rng(is_glass ? 606 : 707);
    const int n = 200000;
    std::vector<double> observed(3, 0.0), expected(3);
    for (int k = 0; k < n; ++k) {
      const auto bs = s.scatter(wo, to_unit_float(rng()), vec2(0.5f));
      int outcome = 2;
      if (bs) {
        outcome = bs->lobe == Lobe::DielectricTransmission ? 1 : 0;
        ASSERT_NEAR(bs->pdf, prob[outcome], 2e-6) << (is_glass ? "glass" : "mirror") << " outcome " << outcome;
      }
      observed[outcome] += 1.0;
    }
    for (int i = 0; i < 3; ++i) expected[i] = n * prob[i];
    EXPECT_TRUE(test::chi2_fit(observed, expected, alpha())) << (is_glass ? "glass" : "mirror");
  }
}

}  // namespace
}  // namespace pathlab
