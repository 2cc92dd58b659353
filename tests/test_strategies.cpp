// Every strategy converges to the same image (label "stat"): the Cornell box
// rendered with each strategy is compared with mis pixel by pixel, with
// z = (a - b) / sqrt(var_a + var_b) against a Šidák-corrected threshold, and
// on the mean over the image.
#include "core/compiled_scene.h"
#include "core/render.h"
#include "reference/reference_tracer.h"
#include "tests/stat_util.h"
#include "tests/test_scenes.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace pathlab {
namespace {

// PATHLAB_STAT_SCALE multiplies the sample counts (CI runs at 1).
int scaled(int spp) {
  const char* s = std::getenv("PATHLAB_STAT_SCALE");
  return spp * (s ? std::max(1, std::atoi(s)) : 1);
}

// The Cornell box with a light four times larger (and four times dimmer):
// with the original small light, cosine and BSDF sampling find it so rarely
// that at test sample counts a pixel's estimate is dominated by a handful of
// hits, its sample variance is unreliable, and a z-test would judge the
// variance estimate rather than the mean.
Film render_strategy(Strategy strategy, int res, int spp, std::uint64_t seed) {
  Scene scene = test::small_cornell(res, spp, FilterKind::Box);
  Shape& light = scene.shapes.back();
  for (vec3& p : light.mesh.positions) p = vec3(2.0f * p.x, p.y, 2.0f * p.z);
  scene.materials[light.material].emission /= 4.0f;
  scene.render.strategy = strategy;
  scene.render.seed = seed;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  Film film(res, res, FilterKind::Box);
  render(tracer, film);
  return film;
}

class StrategiesAgree : public testing::TestWithParam<Strategy> {};

TEST_P(StrategiesAgree, WithMisOnTheCornellBox) {
  constexpr int res = 6;
  const int spp = scaled(4096);
  const Film a = render_strategy(GetParam(), res, spp, 11);
  const Film b = render_strategy(Strategy::Mis, res, spp, 12);  // independent samples
  constexpr double alpha = 1e-3;
  const double z_max = test::sidak_z(alpha, res * res * 3);
  double worst = 0.0;
  dvec3 diff_sum(0.0), var_sum(0.0);
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x)
      for (int c = 0; c < 3; ++c) {
        const double d = double(a.mean(x, y)[c]) - b.mean(x, y)[c];
        const double v = double(a.variance_of_mean(x, y)[c]) + b.variance_of_mean(x, y)[c];
        diff_sum[c] += d;
        var_sum[c] += v;
        if (v > 0.0) worst = std::max(worst, std::abs(d) / std::sqrt(v));
        else EXPECT_NEAR(d, 0.0, 1e-6) << "pixel " << x << "," << y;
      }
  EXPECT_LT(worst, z_max) << "worst per-pixel |z| (threshold " << z_max << ")";
  // Per channel: the channels of one path are correlated.
  for (int c = 0; c < 3; ++c)
    EXPECT_LT(std::abs(diff_sum[c] / std::sqrt(var_sum[c])), test::sidak_z(alpha, 3))
        << "bias of channel " << c << "'s image mean, in standard errors";
}

INSTANTIATE_TEST_SUITE_P(Reference, StrategiesAgree,
                         testing::Values(Strategy::Cosine, Strategy::Bsdf, Strategy::Light, Strategy::LightBsdf),
                         test::strategy_test_name);

}  // namespace
}  // namespace pathlab
