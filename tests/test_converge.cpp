// The speed-accuracy sweep's statistics (label stat): error falls at the
// Monte Carlo rate, clamping is biased, the time budget stops within one
// pass. On the penumbra analytic scene (32x24), a few seconds in all.
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "debugtools/converge.h"
#include "reference/reference_tracer.h"
#include "tests/check_util.h"
#include "wavefront/wavefront_tracer.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pathlab {
namespace {

std::unique_ptr<Tracer> make(const std::string& name, const CompiledScene& scene, const RenderSettings& settings) {
  if (name == "reference") return std::make_unique<ReferenceTracer>(scene, settings);
  if (name == "wavefront") return std::make_unique<WavefrontTracer>(scene, settings);
  throw InputError("unknown tracer '" + name + "'");
}

// Two-sided 99.9% quantile of Student's t with 7 degrees of freedom: the
// seeds' spread over R = 8 seeds is judged with R - 1 degrees of freedom.
constexpr int kSeeds = 8;
constexpr double kT7 = 5.408;

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}
double standard_error(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1) / static_cast<double>(v.size()));
}

class ConvergeSweep : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const Scene scene = load_scene(test::analytic_scene("penumbra-box.json"));
    ConvergeOptions o;
    o.tracers = {"reference", "wavefront"};
    o.strategies = {Strategy::Mis, Strategy::Cosine};
    o.samplers = {SamplerKind::Independent};  // the n^-1/2 rate below is independent sampling's
    o.spp = {4, 16, 64, 256};
    for (int& s : o.spp) s *= test::stat_scale();
    o.seeds = kSeeds;
    // A firefly clamp: MIS's samples here stay below 0.3, cosine's that hit
    // the lamp carry ~10, so the clamp engages for cosine only.
    o.clamps = {0.0f, 1.0f};
    result_ = new ConvergeResult(run_converge(scene, o, make));
  }
  static void TearDownTestSuite() { delete result_; }
  static ConvergeResult* result_;
};
ConvergeResult* ConvergeSweep::result_ = nullptr;

TEST_F(ConvergeSweep, HasOneRowPerConfigurationAndRung) {
  EXPECT_EQ(result_->configs.size(), 2u * 2u * 2u);
  EXPECT_EQ(result_->rows.size(), 2u * 2u * 2u * 4u);
  EXPECT_EQ(result_->compared_pixels, 32u * 24u);
  for (const ConvergeRow& r : result_->rows) {
    EXPECT_EQ(r.rmse_per_seed.size(), static_cast<std::size_t>(kSeeds));
    EXPECT_EQ(r.spp, r.budget) << "an spp rung reaches exactly its spp";
  }
}

// log RMSE against log spp has slope -1/2 for an unbiased estimator. Each
// seed's ladder gives one slope (its rungs are nested, so they are
// correlated within a seed, but seeds are independent); the R slopes'
// mean is compared with -1/2 using their own standard error and Student's
// t at R - 1 degrees of freedom, two-sided alpha = 1e-3 per configuration.
TEST_F(ConvergeSweep, UnclampedRmseFallsAtTheMonteCarloRate) {
  for (std::size_t c = 0; c < result_->configs.size(); ++c) {
    if (result_->configs[c].clamp > 0.0f) continue;
    std::vector<double> spp;
    std::vector<std::vector<double>> per_seed(kSeeds);
    for (const ConvergeRow& r : result_->rows)
      if (r.config == c) {
        spp.push_back(r.spp);
        for (int s = 0; s < kSeeds; ++s) per_seed[s].push_back(r.rmse_per_seed[s]);
      }
    std::vector<double> slopes;
    for (const auto& rmse : per_seed) slopes.push_back(loglog_slope(spp, rmse));
    const double m = mean(slopes), se = standard_error(slopes);
    EXPECT_LE(std::abs(m + 0.5), kT7 * se) << result_->configs[c].label << ": slope " << m << " +- " << se;
    RecordProperty(result_->configs[c].label, std::to_string(m) + " +- " + std::to_string(se));
  }
}

// Clamping removes energy: cosine's clamped bias is significantly below zero
// (z from the seeds' spread, t at R - 1 dof); without the clamp every
// estimator is unbiased.
TEST_F(ConvergeSweep, ClampingShowsBiasAndNoClampDoesNot) {
  for (const ConvergeRow& r : result_->rows) {
    if (r.budget != result_->rows.back().budget) continue;
    const ConvergeConfig& c = result_->configs[r.config];
    const double z = r.bias / r.bias_se;
    RecordProperty(c.label + " bias z", std::to_string(z));
    if (c.clamp > 0.0f && c.strategy == Strategy::Cosine) {
      EXPECT_LT(z, -kT7) << c.label << ": bias " << r.bias << " +- " << r.bias_se;
    } else if (c.clamp == 0.0f) {
      EXPECT_LT(std::abs(z), kT7) << c.label << ": bias " << r.bias << " +- " << r.bias_se;
    }
  }
}

// Depth caps against the uncapped truth: in the furnace (emission Le and
// albedo rho everywhere) a cap of D bounces misses Le rho^(D+1) / (1 - rho)
// per channel, and every path of a capped render carries the same value, so
// the measured bias must be that, up to float32 rounding of the radiance
// (a relative 1e-5 allows ~100 roundings of 6e-8); uncapped (Russian
// roulette) it is unbiased, judged with t at R - 1 dof.
TEST(ConvergeDepthCaps, ShowTheirTruncationBias) {
  Scene scene = load_scene(test::analytic_scene("furnace-sphere.json"));
  scene.film.width = 16;
  scene.film.height = 12;
  ConvergeOptions o;
  o.tracers = {"reference"};
  o.strategies = {};  // the scene's
  o.samplers = {};    // the scene's
  o.spp = {16 * test::stat_scale()};
  o.seeds = kSeeds;
  o.max_depths = {1, 2, -1};
  const ConvergeResult r = run_converge(scene, o, make);
  ASSERT_EQ(r.rows.size(), 3u);
  EXPECT_NE(r.truth.find("uncapped"), std::string::npos) << r.truth;
  const double Le[3] = {0.5, 1.0, 2.0}, rho[3] = {0.8, 0.5, 0.2};
  for (const ConvergeRow& row : r.rows) {
    const int D = r.configs[row.config].max_depth;
    if (D < 0) {
      EXPECT_LT(std::abs(row.bias / row.bias_se), kT7) << "uncapped: " << row.bias << " +- " << row.bias_se;
      continue;
    }
    double missed = 0;
    for (int c = 0; c < 3; ++c) missed += Le[c] * std::pow(rho[c], D + 1) / (1 - rho[c]) / 3;
    EXPECT_NEAR(row.bias, -missed, kT7 * row.bias_se + 1e-5 * missed) << "depth " << D;
  }
}

// The one-seed standard error of the bias on white-sphere-emissive-room.json
// (bilinear film, white: the three channels of a path move together)
// against the spread of the bias over R = 40 seeds. With the true standard
// error sigma, the seeds' sd s has (R - 1) s^2 / sigma^2 ~ chi^2(39), whose
// 0.999 quantile is 72.05: the one-film value (an upper bound) must not be
// below s / sqrt(72.05 / 39). Taking channels and pixels as independent
// gave about half of s, which this catches.
TEST(ConvergeBiasSe, OneSeedIsNotBelowTheSpreadOverSeedsOnTheWhiteSphere) {
  Scene scene = load_scene(test::analytic_scene("white-sphere-emissive-room.json"));
  ASSERT_EQ(scene.film.filter, FilterKind::Bilinear);
  ConvergeOptions o;
  o.tracers = {"reference"};
  o.strategies = {};
  o.samplers = {};
  o.spp = {16 * test::stat_scale()};
  o.seeds = 40;
  const ConvergeResult r = run_converge(scene, o, make);
  ASSERT_EQ(r.rows.size(), 1u);
  // The one-film standard error of each seed, as a one-seed run reports it.
  double one_film = 0.0;
  for (int seed = 0; seed < 8; ++seed) {  // eight one-seed runs give its typical size
    ConvergeOptions one = o;
    one.seeds = 1;
    Scene s = scene;
    s.render.seed += static_cast<std::uint64_t>(seed);
    one_film += run_converge(s, one, make).rows.front().bias_se / 8.0;
  }
  const double s_seeds = r.rows.front().bias_se * std::sqrt(static_cast<double>(o.seeds));
  RecordProperty("one_film_se", std::to_string(one_film));
  RecordProperty("seeds_sd", std::to_string(s_seeds));
  EXPECT_GE(one_film, s_seeds / std::sqrt(72.05 / 39.0)) << "one-film " << one_film << ", spread over seeds " << s_seeds;
}

// render_until with a time budget: stops at a whole pass, within one pass of
// the budget on either side, and counts its spp.
TEST(RenderUntil, TimeBudgetStopsWithinOnePassOfTheBudget) {
  Scene scene = load_scene(test::analytic_scene("penumbra-box.json"));
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  Film film(32, 24, FilterKind::Box);
  StopRule rule;
  rule.time_budget_seconds = 0.5;
  rule.pass_spp = 32;
  const UntilResult r = render_until(tracer, film, rule);
  const double mean_pass = r.stats.seconds / r.passes;
  EXPECT_GT(r.passes, 1u);
  EXPECT_EQ(r.spp, r.passes * rule.pass_spp);
  EXPECT_EQ(film.sample_count(5, 5), r.spp);
  EXPECT_EQ(r.stats.samples, std::uint64_t{r.spp} * 32 * 24);
  EXPECT_GE(r.stats.seconds, rule.time_budget_seconds - mean_pass);
  EXPECT_LE(r.stats.seconds, rule.time_budget_seconds + r.last_pass_seconds);
}

// Extending a film with render_samples gives the same image as one render.
TEST(RenderSamples, ExtendingAFilmEqualsOneRender) {
  Scene scene = load_scene(test::analytic_scene("penumbra-box.json"));
  RenderSettings settings = scene.render;
  settings.spp = 20;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  Film once(32, 24, FilterKind::Box), steps(32, 24, FilterKind::Box);
  render(tracer, once);
  render_samples(tracer, steps, 0, 1);
  render_samples(tracer, steps, 1, 7);
  render_samples(tracer, steps, 7, 20);
  EXPECT_EQ(once.image().pixels, steps.image().pixels);
}

}  // namespace
}  // namespace pathlab
