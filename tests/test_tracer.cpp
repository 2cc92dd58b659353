// The reference tracer against closed-form answers.
#include "core/compiled_scene.h"
#include "core/film.h"
#include "core/render.h"
#include "reference/reference_tracer.h"
#include "tests/test_scenes.h"

#include <gtest/gtest.h>

namespace pathlab {
namespace {

struct FurnaceCase {
  Strategy strategy;
  int max_depth;
  int rr_depth;
};

std::string case_name(const testing::TestParamInfo<FurnaceCase>& info) {
  std::string s = strategy_name(info.param.strategy);
  for (char& c : s)
    if (c == '+') c = '_';
  return s + "_depth" + (info.param.max_depth < 0 ? std::string("inf") : std::to_string(info.param.max_depth)) + "_rr" +
         std::to_string(info.param.rr_depth);
}

class Furnace : public testing::TestWithParam<FurnaceCase> {};

// Inside a closed Lambert sphere with uniform emission Le and albedo rho,
// radiance is the same everywhere: L = Le (1 - rho^(D+1)) / (1 - rho) for a
// depth cap of D bounces, and Le / (1 - rho) without a cap.
TEST_P(Furnace, EveryPixelMatchesTheClosedForm) {
  const FurnaceCase c = GetParam();
  constexpr float Le = 0.75f, rho = 0.6f;
  Scene scene = test::furnace_scene(Le, rho, c.max_depth, c.rr_depth, c.strategy);
  scene.render.spp = 128;
  scene.render.seed = 7;
  const double expected =
      c.max_depth < 0 ? Le / (1.0 - rho) : Le * (1.0 - std::pow(double(rho), c.max_depth + 1)) / (1.0 - rho);

  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  Film film(compiled.scene().film.width, compiled.scene().film.height, FilterKind::Box);
  render(tracer, film);

  // Each pixel within 5 standard errors (plus float rounding for the
  // strategies whose estimate has no variance here), and each channel's
  // image mean within 5 standard errors of its own (per channel: the
  // channels of one path are correlated).
  dvec3 sum(0.0), var_sum(0.0);
  const double n = double(film.width()) * film.height();
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      const Spectrum m = film.mean(x, y), v = film.variance_of_mean(x, y);
      for (int ch = 0; ch < 3; ++ch) {
        const double se = std::sqrt(double(v[ch]));
        EXPECT_NEAR(m[ch], expected, 5.0 * se + 1e-5 * expected) << "pixel " << x << "," << y << " channel " << ch;
        sum[ch] += m[ch];
        var_sum[ch] += v[ch];
      }
    }
  for (int ch = 0; ch < 3; ++ch)
    EXPECT_NEAR(sum[ch] / n, expected, 5.0 * std::sqrt(var_sum[ch]) / n + 1e-5 * expected) << "channel " << ch;
}

std::vector<FurnaceCase> furnace_cases() {
  std::vector<FurnaceCase> cases;
  for (Strategy s : test::kAllStrategies) {
    cases.push_back({s, 0, 100});  // emission only
    cases.push_back({s, 1, 100});  // + direct lighting
    cases.push_back({s, 4, 100});  // capped, no roulette
    cases.push_back({s, 4, 1});    // capped, roulette after one bounce
    cases.push_back({s, -1, 2});   // no cap: Russian roulette alone ends paths
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(AllStrategies, Furnace, testing::ValuesIn(furnace_cases()), case_name);

// A sphere inside a uniformly lit world, seen by the camera: every pixel whose
// footprint lies entirely on the sphere should be `on`, entirely off it
// `off`. Pixels the silhouette crosses are skipped.
void expect_sphere_image(const Scene& scene_in, const Spectrum& on, const Spectrum& off) {
  Scene scene = scene_in;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  const int w = compiled.scene().film.width, h = compiled.scene().film.height;
  Film film(w, h, FilterKind::Box);
  render(tracer, film);
  int checked_on = 0, checked_off = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      int hits = 0;
      for (const vec2 c : {vec2(0, 0), vec2(1, 0), vec2(0, 1), vec2(1, 1)}) {
        Surfel s;
        hits += compiled.intersect(compiled.camera().generate_ray(vec2(float(x), float(y)) + c, vec2(0.5f)), &s) &&
                s.shape == 0;
      }
      if (hits != 0 && hits != 4) continue;
      const Spectrum expected = hits == 4 ? on : off;
      (hits == 4 ? checked_on : checked_off)++;
      const Spectrum m = film.mean(x, y), v = film.variance_of_mean(x, y);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(m[c], expected[c], 5.0 * std::sqrt(double(v[c])) + 1e-5 * expected[c])
            << "pixel " << x << "," << y << " channel " << c;
    }
  EXPECT_GT(checked_on, 10);
  EXPECT_GT(checked_off, 10);
}

class EnvironmentSphere : public testing::TestWithParam<Strategy> {};

// A Lambert sphere of albedo a under a uniform environment L: being convex it
// sees only the environment, so it shows a * L; the background shows L.
TEST_P(EnvironmentSphere, ShowsAlbedoTimesEnvironment) {
  const Scene scene = parse_scene(R"({
    "pathlab_scene": 1,
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov_y": 40},
    "film": {"resolution": [16, 16]},
    "render": {"spp": 64, "max_depth": 3, "seed": 3, "strategy": ")" + std::string(strategy_name(GetParam())) + R"("},
    "materials": {"grey": {"type": "diffuse", "albedo": [0.3, 0.6, 0.9]}},
    "shapes": [{"type": "sphere", "radius": 1, "material": "grey"}],
    "lights": [{"type": "environment", "radiance": [2, 1, 0.5]}]
  })", "env-sphere.json");
  expect_sphere_image(scene, Spectrum(0.6f, 0.6f, 0.45f), Spectrum(2.0f, 1.0f, 0.5f));
}

class MirrorSphere : public testing::TestWithParam<Strategy> {};

// A mirror sphere of reflectance R in a closed room whose black walls emit
// Le: the sphere shows R * Le (the impulse is sampled with probability
// mean(R), weight R / mean(R)), the walls Le.
TEST_P(MirrorSphere, ShowsReflectanceTimesRoom) {
  const Scene scene = parse_scene(R"({
    "pathlab_scene": 1,
    "camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "fov_y": 50},
    "film": {"resolution": [16, 16]},
    "render": {"spp": 64, "max_depth": 2, "seed": 5, "strategy": ")" + std::string(strategy_name(GetParam())) + R"("},
    "materials": {"mirror": {"type": "mirror", "reflectance": [0.9, 0.5, 0.2]},
                  "walls": {"type": "emissive", "radiance": [1.5, 1.5, 1.5]}},
    "shapes": [{"type": "sphere", "radius": 1, "material": "mirror"},
               {"type": "box", "material": "walls", "flip_normals": true, "transform": {"scale": 5}}]
  })", "mirror-room.json");
  expect_sphere_image(scene, Spectrum(1.35f, 0.75f, 0.3f), Spectrum(1.5f));
}

INSTANTIATE_TEST_SUITE_P(AllStrategies, EnvironmentSphere, testing::ValuesIn(test::kAllStrategies),
                         test::strategy_test_name);
INSTANTIATE_TEST_SUITE_P(AllStrategies, MirrorSphere, testing::ValuesIn(test::kAllStrategies),
                         test::strategy_test_name);

}  // namespace
}  // namespace pathlab
