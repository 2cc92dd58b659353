// Spot and directional lights against closed forms, delta-light selection
// against the probability the estimators divide by.
#include "core/compiled_scene.h"
#include "core/light_sampler.h"
#include "core/rng.h"
#include "core/scene_loader.h"
#include "debugtools/path_recorder.h"
#include "reference/reference_tracer.h"
#include "tests/stat_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace pathlab {
namespace {

// A Lambert floor (albedo 0.5, y = 0, 20 x 20) seen from straight above,
// direct light only, lit by `lights` (JSON) and shaded by `extra_shapes`.
Scene floor_scene(const std::string& lights, const std::string& extra_shapes = "") {
  const std::string text = R"({
    "pathlab_scene": 1,
    "camera": {"position": [0, 6, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov_y": 90},
    "film": {"resolution": [24, 24]},
    "render": {"spp": 2, "max_depth": 1, "strategy": "light"},
    "materials": {"floor": {"type": "diffuse", "albedo": 0.5}},
    "shapes": [{"type": "rectangle", "material": "floor",
                "transform": [{"rotate": {"axis": [1, 0, 0], "angle": -90}}, {"scale": 10}]})" +
                           extra_shapes + R"(],
    "lights": [)" + lights + "]}";
  return parse_scene(text, "floor.json");
}

// Records the first surface a camera ray hits.
struct FirstHit final : PathObserver {
  std::optional<vec3> p;
  void on_hit(const HitEvent& e) override {
    if (e.vertex == 1) p = e.p;
  }
};

// Every sample of the reference tracer on `scene`: the radiance it returns
// against `expected(p)` at the point it hit, within rounding. `skip(p)`
// leaves out points on a shadow's edge.
template <class Expected, class Skip>
void expect_every_sample(const Scene& scene_in, Expected expected, Skip skip) {
  Scene scene = scene_in;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  int compared = 0, lit = 0;
  for (std::uint32_t y = 0; y < 24; ++y)
    for (std::uint32_t x = 0; x < 24; ++x)
      for (std::uint32_t k = 0; k < 2; ++k) {
        FirstHit hit;
        const FilmSample fs = tracer.trace_sample(x, y, k, &hit);
        ASSERT_TRUE(hit.p.has_value()) << x << "," << y;
        if (skip(*hit.p)) continue;
        const Spectrum want = expected(*hit.p);
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(fs.L[c], want[c], 2e-5f * want[c] + 1e-7f) << "pixel " << x << "," << y << " sample " << k
                                                                   << " at " << hit.p->x << "," << hit.p->z;
        ++compared;
        lit += want[0] > 0.0f;
      }
  EXPECT_GT(compared, 1000);
  EXPECT_GT(lit, 100);
}

TEST(DeltaLights, SpotProfileIsASmoothstepInCosTheta) {
  const float co = std::cos(glm::radians(40.0f)), ci = std::cos(glm::radians(20.0f));
  EXPECT_EQ(spot_profile(1.0f, co, ci), 1.0f);
  EXPECT_EQ(spot_profile(ci, co, ci), 1.0f);
  EXPECT_EQ(spot_profile(co, co, ci), 0.0f);
  EXPECT_EQ(spot_profile(0.0f, co, ci), 0.0f);
  EXPECT_NEAR(spot_profile(0.5f * (co + ci), co, ci), 0.5f, 1e-6f);
  EXPECT_NEAR(spot_profile(co + 0.25f * (ci - co), co, ci), 0.15625f, 1e-5f);  // 3 t^2 - 2 t^3 at t = 1/4
  // A hard edge when the two angles are equal.
  EXPECT_EQ(spot_profile(std::nextafter(co, 1.0f), co, co), 1.0f);
  EXPECT_EQ(spot_profile(std::nextafter(co, 0.0f), co, co), 0.0f);
}

// Under a spot at height h shining straight down, the floor's radiance at a
// point at distance r is rho / pi * I * profile(theta) * cos(theta) / r^2.
TEST(DeltaLights, SpotLightsALambertFloorAsTheClosedForm) {
  const Scene scene = floor_scene(R"({"type": "spot", "position": [0.5, 3, -0.25], "look_at": [0.5, 0, -0.25],
      "intensity": [6, 3, 1.5], "cone_angle": 40, "falloff_start": 20})");
  const float co = std::cos(glm::radians(40.0f)), ci = std::cos(glm::radians(20.0f));
  expect_every_sample(
      scene,
      [&](const vec3& p) {
        const vec3 d = vec3(0.5f, 3.0f, -0.25f) - p;
        const float r2 = glm::dot(d, d), cos_theta = 3.0f / std::sqrt(r2);
        return Spectrum(6.0f, 3.0f, 1.5f) * (0.5f / kPi * spot_profile(cos_theta, co, ci) * cos_theta / r2);
      },
      [](const vec3&) { return false; });
}

// A directional light whose light travels at theta from the normal: the
// floor's radiance is rho / pi * E * cos(theta), except in the shadow of a
// square 20 units up along the light, which an unbounded shadow ray finds.
TEST(DeltaLights, DirectionalLightsALambertFloorAsTheClosedFormAndCastsFarShadows) {
  const float theta = glm::radians(30.0f);
  const vec3 travel(std::sin(theta), -std::cos(theta), 0.0f);
  const std::string dir = "[" + std::to_string(travel.x) + ", " + std::to_string(travel.y) + ", 0]";
  // The blocker: [-2, 2]^2 at y = 20, moved against the light so that its
  // shadow falls on [-2, 2]^2 of the floor.
  const float shift = 20.0f * std::tan(theta);
  const Scene scene = floor_scene(R"({"type": "directional", "direction": )" + dir + R"(, "irradiance": [2, 1, 4]})",
                                  R"(, {"type": "rectangle", "material": "floor", "transform": [
                                       {"rotate": {"axis": [1, 0, 0], "angle": 90}}, {"scale": 2},
                                       {"translate": [)" + std::to_string(-shift) + ", 20, 0]}]}");
  const vec3 wi = -glm::normalize(travel);
  const auto shadowed = [](const vec3& p) { return std::abs(p.x) < 2.0f && std::abs(p.z) < 2.0f; };
  expect_every_sample(
      scene,
      [&](const vec3& p) {
        return shadowed(p) ? Spectrum(0.0f) : Spectrum(2.0f, 1.0f, 4.0f) * (0.5f / kPi * wi.y);
      },
      [](const vec3& p) { return std::abs(std::abs(p.x) - 2.0f) < 1e-2f || std::abs(std::abs(p.z) - 2.0f) < 1e-2f; });
}

// Point, spot and directional lights of unequal powers: picked in
// proportion to the documented power estimates, and as often as the pmf
// that sample_delta reports (chi-square, 2 degrees of freedom).
TEST(DeltaLights, PickedByPowerAsOftenAsThePmfSays) {
  const Scene scene = floor_scene(R"({"type": "point", "position": [0, 2, 0], "intensity": 1},
      {"type": "spot", "position": [0, 3, 0], "direction": [0, -1, 0], "intensity": 6, "cone_angle": 30, "falloff_start": 10},
      {"type": "directional", "direction": [0, -1, 0.2], "irradiance": [0.05, 0.01, 0.02]})");
  const CompiledScene compiled(scene);
  const LightSampler& lights = compiled.lights();
  ASSERT_EQ(lights.delta_pmf().size(), 3u);
  const double r = compiled.bounds_radius();
  const double c30 = std::cos(glm::radians(30.0)), c10 = std::cos(glm::radians(10.0));
  const double power[3] = {4.0 * kPi * 1.0, 2.0 * kPi * 6.0 * (1.0 - (c10 + c30) / 2.0),
                           kPi * r * r * luminance(Spectrum(0.05f, 0.01f, 0.02f))};
  const double total = power[0] + power[1] + power[2];
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(lights.delta_pmf()[i], power[i] / total, 1e-6) << i;
  const auto [lo, hi] = std::minmax_element(lights.delta_pmf().begin(), lights.delta_pmf().end());
  EXPECT_GT(*lo, 0.05f);  // unequal, none negligible
  EXPECT_GT(*hi, 2.0f * *lo);

  std::mt19937_64 rng(19);
  const int n = 200000;
  double counts[3] = {0, 0, 0};
  for (int k = 0; k < n; ++k) {
    const auto ls = lights.sample_delta(vec3(0.0f, 0.0f, 0.0f), to_unit_float(rng()));
    ASSERT_TRUE(ls.has_value());
    EXPECT_EQ(ls->pdf, lights.delta_pmf()[ls->light]);
    counts[ls->light] += 1.0;
  }
  double chi2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double e = n * double(lights.delta_pmf()[i]);
    chi2 += (counts[i] - e) * (counts[i] - e) / e;
  }
  EXPECT_LT(chi2, 13.8) << counts[0] << " " << counts[1] << " " << counts[2];  // alpha = 1e-3, 2 dof
}

TEST(DeltaLights, DirectionalSampleIsAnEscapeWithPdfTheChoice) {
  const Scene scene = floor_scene(R"({"type": "directional", "direction": [0, -2, 0], "irradiance": 3})");
  const CompiledScene compiled(scene);
  const auto ls = compiled.lights().sample_delta(vec3(1.0f, 0.0f, 2.0f), 0.5f);
  ASSERT_TRUE(ls.has_value());
  EXPECT_TRUE(ls->infinite);
  EXPECT_TRUE(std::isinf(ls->dist));
  EXPECT_EQ(ls->wi, vec3(0, 1, 0));
  EXPECT_EQ(ls->Le, Spectrum(3.0f));
  EXPECT_EQ(ls->pdf, 1.0f);
}

TEST(DeltaLights, OutsideTheSpotsConeNothingIsSampled) {
  const Scene scene = floor_scene(R"({"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0],
      "intensity": 1, "cone_angle": 45})");
  const CompiledScene compiled(scene);
  EXPECT_TRUE(compiled.lights().sample_delta(vec3(0.9f, 0.0f, 0.0f), 0.5f).has_value());
  EXPECT_FALSE(compiled.lights().sample_delta(vec3(1.1f, 0.0f, 0.0f), 0.5f).has_value());
}

// trace-pixel names the kind of delta light a vertex sampled (its index
// counts the delta lights of non-zero intensity, a black one skipped).
TEST(DeltaLights, TracePixelNamesTheKind) {
  const Scene scene = floor_scene(R"({"type": "point", "position": [0, 2, 0], "intensity": 0},
      {"type": "spot", "position": [0, 3, 0], "direction": [0, -1, 0], "intensity": 500, "cone_angle": 60},
      {"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 2})");
  const CompiledScene compiled(scene);
  const ReferenceTracer tracer(compiled, scene.render);
  std::set<std::string> kinds;
  // Picked in proportion to power: the spot 2 pi 500 (1 - cos 60), the sun
  // pi 10^2 2 (the floor's bounding radius is about 10): both within 64 samples.
  for (std::uint32_t s = 0; s < 64; ++s) {
    PathRecorder path;
    tracer.trace_sample(12, 12, s, &path);
    const nlohmann::json j = path_to_json(TraceHeader{"floor", "reference", 12, 12, s, scene.render, 24, 24}, path, scene);
    for (const nlohmann::json& e : j["events"])
      if (e["type"] == "light") kinds.insert(e["kind"].get<std::string>());
    const std::string text = path_to_text(TraceHeader{"floor", "reference", 12, 12, s, scene.render, 24, 24}, path, scene);
    EXPECT_EQ(text.find("light    point"), std::string::npos) << text;
  }
  EXPECT_EQ(kinds, (std::set<std::string>{"spot", "directional"}));
}

// ------------------------------------------------------------ sun disks

// A directional light with an angular diameter is no delta light: the light
// sampler samples it as an infinite light a ray can hit.
TEST(SunDisk, IsNotADeltaLight) {
  const Scene scene = floor_scene(R"({"type": "directional", "direction": [0, -1, 0], "irradiance": 1, "angular_diameter": 0.53},
                                     {"type": "directional", "direction": [0, -1, 0], "irradiance": 1})");
  ASSERT_EQ(scene.delta_lights.size(), 2u);
  EXPECT_TRUE(scene.delta_lights[0].is_sun_disk());
  EXPECT_NEAR(scene.delta_lights[0].angular_radius, 0.265 * M_PI / 180.0, 1e-7);
  EXPECT_FALSE(scene.delta_lights[1].is_sun_disk());
  EXPECT_EQ(sampled_delta_lights(scene).size(), 1u);
  const CompiledScene compiled{Scene(scene)};
  EXPECT_TRUE(compiled.lights().samples_environment());
  EXPECT_EQ(compiled.lights().delta_pmf().size(), 1u);
}

// Uniform in the cone: 1 - cos theta (from the sine, exact for a tiny disk)
// over 1 - cos alpha, and phi about the axis, are uniform on [0, 1); chi-square
// over 10 x 8 equal bins, for the sun's 0.53 degrees and a 40 degree disk. Every
// sample carries the disk's radiance E / (pi sin^2 alpha) and the density
// 1 / (2 pi (1 - cos alpha)) that pdf_environment gives its direction, and a
// direction just outside the cone has neither.
TEST(SunDisk, ConeSamplingIsUniformAndMatchesItsPdf) {
  for (const double diameter : {0.53, 40.0}) {
    SCOPED_TRACE(diameter);
    const Scene scene = floor_scene(R"({"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": [2, 1, 0.5],
                                       "angular_diameter": )" + std::to_string(diameter) + "}");
    const CompiledScene compiled{Scene(scene)};
    const LightSampler& lights = compiled.lights();
    const dvec3 axis = -glm::normalize(dvec3(0.3, -1, 0.2));
    const double alpha = 0.5 * diameter * M_PI / 180.0;
    const double one_minus_cos = 2.0 * std::pow(std::sin(0.5 * alpha), 2);
    const double pdf = 1.0 / (2.0 * M_PI * one_minus_cos);
    const dvec3 Le = dvec3(2, 1, 0.5) / (M_PI * std::pow(std::sin(alpha), 2));
    const Frame frame{vec3(axis)};
    constexpr int kBinsT = 10, kBinsPhi = 8, kN = 80000;
    std::vector<long> counts(kBinsT * kBinsPhi, 0);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    for (int k = 0; k < kN; ++k) {
      const auto ls = lights.sample(vec3(0.0f), uniform(rng), vec2(uniform(rng), uniform(rng)));
      ASSERT_TRUE(ls) << k;
      ASSERT_TRUE(ls->infinite);
      EXPECT_NEAR(ls->pdf, pdf, 1e-4 * pdf);
      EXPECT_NEAR(ls->pdf, lights.pdf_environment(ls->wi), 1e-6f * ls->pdf);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(ls->Le[c], Le[c], 1e-5 * Le[c]);
      const dvec3 w(ls->wi);
      const double sin2 = glm::dot(glm::cross(w, axis), glm::cross(w, axis)), cos_theta = glm::dot(w, axis);
      const double t = sin2 / (1.0 + cos_theta) / one_minus_cos;  // (1 - cos theta) / (1 - cos alpha)
      double phi = std::atan2(glm::dot(w, dvec3(frame.t)), glm::dot(w, dvec3(frame.s)));
      if (phi < 0.0) phi += 2.0 * M_PI;
      const int bt = std::min(kBinsT - 1, static_cast<int>(t * kBinsT));
      const int bp = std::min(kBinsPhi - 1, static_cast<int>(phi / (2.0 * M_PI) * kBinsPhi));
      ASSERT_LE(t, 1.0 + 1e-4) << k;
      ++counts[bt * kBinsPhi + bp];
    }
    const double stat = test::chi2_equal(counts, kN);
    EXPECT_LT(stat, test::chi2_critical(kBinsT * kBinsPhi - 1, 0.01));
    // Just outside the rim: nothing; just inside: the disk.
    const float s_out = static_cast<float>(std::sin(alpha * 1.001)), s_in = static_cast<float>(std::sin(alpha * 0.999));
    const vec3 out = glm::normalize(frame.n * std::sqrt(1.0f - s_out * s_out) + frame.s * s_out);
    const vec3 in = glm::normalize(frame.n * std::sqrt(1.0f - s_in * s_in) + frame.s * s_in);
    EXPECT_EQ(lights.environment(out), Spectrum(0.0f));
    EXPECT_EQ(lights.pdf_environment(out), 0.0f);
    EXPECT_NEAR(lights.environment(in).x, Le.x, 1e-5 * Le.x);
    EXPECT_GT(lights.pdf_environment(in), 0.0f);
  }
}

}  // namespace
}  // namespace pathlab
