// The speed-accuracy sweep behind `pathlab converge`: renders a scene with
// every configuration (tracer x strategy x clamp x depth cap) at every
// budget (a samples-per-pixel ladder and wall-clock budgets) over R seeds,
// and measures each against the ground truth (the scene's analytic expected
// image, or a reference EXR). Formulas and columns: docs/converge.md.
#pragma once

#include "core/image_io.h"
#include "core/scene.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab {

class Tracer;
class CompiledScene;

// Builds a tracer by name; throws InputError for an unknown one.
using TracerFactory =
    std::function<std::unique_ptr<Tracer>(const std::string& name, const CompiledScene&, const RenderSettings&)>;

class Film;

struct ConvergeOptions {
  // By default both tracers, all five strategies and both samplers: the
  // choices a user has. An empty strategies or samplers list: the scene's.
  std::vector<std::string> tracers{"reference", "wavefront"};
  std::vector<Strategy> strategies{std::begin(kAllStrategies), std::end(kAllStrategies)};
  std::vector<SamplerKind> samplers{SamplerKind::Independent, SamplerKind::ZSobol};
  // How a point on a picked area light is sampled (render.light_sampling);
  // empty: the scene's. Each value compiles the scene once more.
  std::vector<LightSampling> light_samplings;
  // How an area light is picked (render.light_sampler: power, bvh); empty:
  // the scene's. Each value compiles the scene once more too.
  std::vector<LightSamplerKind> light_samplers;
  std::vector<int> spp{1, 4, 16, 64, 256, 1024};  // the ladder (progressive: each rung extends the last)
  std::vector<double> time_budgets;     // seconds, each rendered from scratch with render_until()
  int seeds = 4;                        // R: seeds scene.render.seed, +1, ..., +R-1
  std::vector<float> clamps{0.0f};      // radiance clamp per configuration, 0 = off
  std::vector<int> max_depths;          // depth caps; empty: the scene's. Non-empty: truth is uncapped
  bool exclude_emitters = false;        // leave out pixels that see an emitter directly
  std::filesystem::path reference;      // ground-truth EXR; empty: the analytic model
};

// One configuration: what a curve of the plots follows.
struct ConvergeConfig {
  std::string tracer;
  Strategy strategy = Strategy::Mis;
  float clamp = 0.0f;
  int max_depth = 0;
  std::string label;  // "reference mis", "+ clamp 4", "+ depth 2", "+ zsobol" when the sweep varies them
  SamplerKind sampler = SamplerKind::Independent;
  LightSampling light_sampling = LightSampling::Area;
  LightSamplerKind light_sampler = LightSamplerKind::Power;
};

// One budget of one configuration, averaged over the seeds.
struct ConvergeRow {
  std::size_t config = 0;       // index into ConvergeResult::configs
  bool time_budget = false;     // false: an spp rung
  double budget = 0.0;          // spp, or seconds
  double spp = 0.0;             // mean samples per pixel reached
  double seconds = 0.0;         // mean wall time of the render (cumulative over the ladder)
  double samples_per_second = 0.0;
  double rmse = 0.0, rmse_sd = 0.0;  // mean over seeds, standard deviation over seeds
  double rel_mse = 0.0;         // mean over seeds
  double bias = 0.0, bias_se = 0.0;
  double efficiency = 0.0;      // 1 / (rel_mse * seconds)
  std::vector<double> rmse_per_seed;
  std::vector<double> seconds_per_seed;
};

struct ConvergeResult {
  std::string scene;
  std::string truth;  // "analytic <model>", "analytic <model>, uncapped", "reference <file>"
  int width = 0, height = 0;
  std::size_t compared_pixels = 0;   // pixels in the metrics (all unless --exclude-emitters)
  int seeds = 0;
  std::vector<ConvergeConfig> configs;
  std::vector<ConvergeRow> rows;      // config-major, then spp rungs, then time budgets
};

// Runs the sweep. Checks everything that can be checked before rendering
// (tracer names, spp >= 1, budgets > 0, seeds >= 1, reference size, a truth
// to compare with) and throws InputError naming the problem. `log` receives
// one line per configuration.
ConvergeResult run_converge(const Scene& scene, const ConvergeOptions& options, const TracerFactory& make_tracer,
                            const std::function<void(const std::string&)>& log = {});

// The table as CSV (header + one line per row) and as Markdown.
std::string converge_csv(const ConvergeResult& result);
std::string converge_markdown(const ConvergeResult& result);

// The configuration whose mean RMSE first falls to `target_rmse`, by the
// time it takes (log-log interpolation between budgets, over spp rungs and
// time budgets); nullopt if none reaches it.
struct FirstToReach {
  std::size_t config = 0;
  double seconds = 0.0;
  bool at_first_budget = false;  // below the target at its first point: seconds is an upper bound
};
std::optional<FirstToReach> first_to_reach(const ConvergeResult& result, double target_rmse);
// The default target: the smallest RMSE any configuration has at its first
// (cheapest) point, so the configuration that has it reaches it at a
// measured time and every other one either crosses it between two measured
// points or never reaches it.
double default_target_rmse(const ConvergeResult& result);

// Configurations whose curves the seeds cannot tell apart from `config`'s:
// at every budget the paired per-seed RMSE differences (same seeds, so
// paired) have a mean within t * their standard error, and at every spp
// rung the mean times differ by less than t * the standard error of that
// difference (Welch), t the two-sided Student quantile at R - 1 degrees of
// freedom for alpha = 0.01, Sidak-corrected over the budgets. With R = 1
// there is no spread to judge by: only configurations with the same RMSE at
// every budget (the same paths) are listed, whatever their times.
std::vector<std::size_t> indistinguishable_from(const ConvergeResult& result, std::size_t config);

// "first to reach RMSE X: **label**, in about T s", or, when configurations
// are indistinguishable_from() the first, "no winner among **a, b**,
// statistically indistinguishable (...)", or that none reached it.
std::string first_to_reach_text(const ConvergeResult& result, double target_rmse);

// The standard error of the bias measured on one film (the mean over its
// compared pixels and channels of est - truth; pixels where `truth` is NaN
// are left out), from the film's per-pixel variances of the mean:
//   SE = k sqrt(sum_pixels (sum_c sd_c)^2) / N,
// N the pixel-channels compared. A path's three channels are correlated,
// so each pixel's channel sum has variance at most (sum_c sd_c)^2 (exact
// when the channels move together, as in a white scene); with the bilinear
// filter a sample reaches up to 4 pixels, so each pixel correlates with its
// 8 neighbours and k = 3 bounds the inflation (the covariances bounded by
// the variances, as check.h does); k = 1 for the box filter. An upper bound
// then, exact for a box film whose channels are equal.
double one_film_bias_se(const Film& film, const Image& truth);

// Mean, sample standard deviation and standard error of the mean of
// values drawn independently (the seeds).
struct SeedSpread {
  double mean = 0.0, sd = 0.0, se = 0.0;
};
SeedSpread seed_spread(const std::vector<double>& values);

// Two-sided Student t quantile: |T| beyond it has probability p, with dof
// degrees of freedom.
double student_two_sided_quantile(double p, int dof);

// Least-squares slope of log y against log x (points with x, y > 0).
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y);

// Writes converge.csv, converge.md, rmse-vs-time.svg and rmse-vs-spp.svg
// into `dir` (each through a temporary file). Throws InputError if `dir`
// cannot be written.
void write_converge_report(const std::filesystem::path& dir, const ConvergeResult& result);

}  // namespace pathlab
