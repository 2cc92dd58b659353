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
  // strategies whose estimate has no variance here), and the image mean
  // within 5 standard errors of its own.
  double sum = 0.0, var_sum = 0.0;
  int n = 0;
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      const Spectrum m = film.mean(x, y), v = film.variance_of_mean(x, y);
      for (int ch = 0; ch < 3; ++ch) {
        const double se = std::sqrt(double(v[ch]));
        EXPECT_NEAR(m[ch], expected, 5.0 * se + 1e-5 * expected) << "pixel " << x << "," << y << " channel " << ch;
        sum += m[ch];
        var_sum += v[ch];
        ++n;
      }
    }
  const double mean = sum / n, se_mean = std::sqrt(var_sum) / n;
  EXPECT_NEAR(mean, expected, 5.0 * se_mean + 1e-5 * expected);
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

}  // namespace
}  // namespace pathlab
