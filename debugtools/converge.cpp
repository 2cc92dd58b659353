#include "debugtools/converge.h"

#include "analytic-scenes/analytic_model.h"
#include "analytic-scenes/expected_image.h"
#include "core/compiled_scene.h"
#include "core/film.h"
#include "core/error.h"
#include "core/render.h"
#include "core/tracer.h"
#include "debugtools/image_metrics.h"
#include "debugtools/plot_svg.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <utility>

namespace pathlab {

namespace {

struct Truth {
  Image image;
  std::string description;
};

Truth find_truth(const Scene& scene, const ConvergeOptions& options) {
  if (!options.reference.empty()) {
    Truth t{read_image(options.reference), "reference " + options.reference.string()};
    if (t.image.width != scene.film.width || t.image.height != scene.film.height)
      throw InputError("--reference " + options.reference.string() + " is " + std::to_string(t.image.width) + "x" +
                       std::to_string(t.image.height) + " but the scene renders " + std::to_string(scene.film.width) +
                       "x" + std::to_string(scene.film.height));
    return t;
  }
  if (scene.analytic.empty())
    throw InputError((scene.file.empty() ? scene.name : scene.file.string()) +
                     ": the scene names no analytic model, so there is no ground truth; give one with --reference ref.exr");
  Scene truth_scene = scene;
  const bool uncapped = !options.max_depths.empty();
  if (uncapped) truth_scene.render.max_depth = -1;
  std::unique_ptr<AnalyticModel> model;
  try {
    model = make_analytic_model(truth_scene);
  } catch (const InputError& e) {
    if (!uncapped) throw;
    throw InputError(std::string("--max-depths needs the uncapped answer, which the analytic model cannot give: ") +
                     e.what() + "; give a reference EXR of the uncapped image with --reference");
  }
  const Camera camera(truth_scene.camera, truth_scene.film.width, truth_scene.film.height);
  return {expected_image(*model, camera, truth_scene.film).mean,
          "analytic " + std::string(model->name()) + (uncapped ? ", uncapped" : "")};
}

std::string config_label(const ConvergeConfig& c, const ConvergeOptions& o) {
  std::string label = c.tracer + " " + strategy_name(c.strategy);
  if (o.clamps.size() > 1 || o.clamps.front() > 0.0f) {
    std::ostringstream s;
    s << " clamp " << c.clamp;
    label += c.clamp > 0.0f ? s.str() : " no clamp";
  }
  if (!o.max_depths.empty()) label += " depth " + std::to_string(c.max_depth);
  if (o.samplers.size() > 1 || c.sampler != SamplerKind::Independent) label += std::string(" ") + sampler_name(c.sampler);
  if (o.light_samplings.size() > 1 || c.light_sampling != LightSampling::Area)
    label += std::string(" ") + light_sampling_name(c.light_sampling);
  if (o.light_samplers.size() > 1 || c.light_sampler != LightSamplerKind::Power)
    label += std::string(" ") + light_sampler_name(c.light_sampler);
  return label;
}

// Pixels that see an emitter directly: any emission in a 4-spp render with
// no bounce at all (max_depth 0), so edge pixels partly covered count too.
std::vector<bool> emitter_mask(const Scene& scene, const CompiledScene& compiled, const std::string& tracer_name,
                               const TracerFactory& make_tracer) {
  RenderSettings s = scene.render;
  s.max_depth = 0;
  s.clamp = 0.0f;
  const auto tracer = make_tracer(tracer_name, compiled, s);
  Film film(scene.film.width, scene.film.height, scene.film.filter);
  render_samples(*tracer, film, 0, 4);
  std::vector<bool> mask(static_cast<std::size_t>(scene.film.width) * scene.film.height);
  for (int y = 0; y < scene.film.height; ++y)
    for (int x = 0; x < scene.film.width; ++x) {
      const Spectrum m = film.mean(x, y);
      mask[static_cast<std::size_t>(y) * scene.film.width + x] = std::max({m.x, m.y, m.z}) > 0.0f;
    }
  return mask;
}

struct Measure {
  double rmse, rel_mse, bias, bias_se_pixels;
};

// Excluded pixels are NaN in both images, which compare_images leaves out.
Measure measure(const Film& film, const Image& truth) {
  Image est = film.image();
  for (int y = 0; y < est.height; ++y)
    for (int x = 0; x < est.width; ++x)
      if (!std::isfinite(truth.at(x, y).x)) est.at(x, y) = vec3(std::numeric_limits<float>::quiet_NaN());
  const ImageMetrics m = compare_images(est, truth);
  return {m.rmse, m.rel_mse, m.mean_a - m.mean_b, one_film_bias_se(film, truth)};
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double sample_sd(const std::vector<double>& v) {
  if (v.size() < 2) return 0.0;
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

// Regularised incomplete beta I_x(a, b) by its continued fraction
// (Numerical Recipes' betacf), for Student's t tail.
double incomplete_beta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x));
  const auto cf = [](double aa, double bb, double xx) {
    double c = 1.0, d = 1.0 - (aa + bb) * xx / (aa + 1.0);
    d = 1.0 / (std::abs(d) < 1e-300 ? 1e-300 : d);
    double h = d;
    for (int m = 1; m < 300; ++m) {
      const double m2 = 2.0 * m;
      double num = m * (bb - m) * xx / ((aa + m2 - 1.0) * (aa + m2));
      d = 1.0 + num * d, c = 1.0 + num / c;
      d = 1.0 / (std::abs(d) < 1e-300 ? 1e-300 : d);
      h *= d * c;
      num = -(aa + m) * (aa + bb + m) * xx / ((aa + m2) * (aa + m2 + 1.0));
      d = 1.0 + num * d, c = 1.0 + num / c;
      d = 1.0 / (std::abs(d) < 1e-300 ? 1e-300 : d);
      const double del = d * c;
      h *= del;
      if (std::abs(del - 1.0) < 1e-15) break;
    }
    return h;
  };
  return x < (a + 1.0) / (a + b + 2.0) ? front * cf(a, b, x) / a : 1.0 - front * cf(b, a, 1.0 - x) / b;
}

struct SeedPoint {
  double spp, seconds, samples, rmse, rel_mse, bias, bias_se_pixels;
};

ConvergeRow summarise(std::size_t config, bool time_budget, double budget, const std::vector<SeedPoint>& seeds) {
  ConvergeRow r;
  r.config = config;
  r.time_budget = time_budget;
  r.budget = budget;
  std::vector<double> spp, sec, samples, rel, bias;
  for (const SeedPoint& p : seeds) {
    spp.push_back(p.spp);
    sec.push_back(p.seconds);
    samples.push_back(p.samples);
    r.rmse_per_seed.push_back(p.rmse);
    r.seconds_per_seed.push_back(p.seconds);
    rel.push_back(p.rel_mse);
    bias.push_back(p.bias);
  }
  r.spp = mean(spp);
  r.seconds = mean(sec);
  r.samples_per_second = mean(samples) / std::max(r.seconds, 1e-12);
  r.rmse = mean(r.rmse_per_seed);
  r.rmse_sd = sample_sd(r.rmse_per_seed);
  r.rel_mse = mean(rel);
  r.bias = mean(bias);
  // With two or more seeds the standard error comes from their spread; with
  // one, from the film's per-pixel variances.
  r.bias_se = seeds.size() >= 2 ? seed_spread(bias).se : seeds.front().bias_se_pixels;
  // An exact estimator (relMSE 0) is infinitely efficient, and says so.
  r.efficiency = r.rel_mse * r.seconds > 0.0 ? 1.0 / (r.rel_mse * r.seconds) : std::numeric_limits<double>::infinity();
  return r;
}

void validate(const ConvergeOptions& o) {
  if (o.tracers.empty()) throw InputError("--tracers: give at least one tracer");
  if (o.spp.empty() && o.time_budgets.empty()) throw InputError("give at least one budget: --spp or --time-budgets");
  for (int s : o.spp)
    if (s < 1) throw InputError("--spp " + std::to_string(s) + ": samples per pixel must be at least 1");
  for (std::size_t i = 1; i < o.spp.size(); ++i)
    if (o.spp[i] <= o.spp[i - 1]) throw InputError("--spp: the ladder must increase (each rung extends the last)");
  for (double t : o.time_budgets)
    if (!(t > 0.0) || !std::isfinite(t)) throw InputError("--time-budgets: each budget must be a positive number of seconds");
  if (o.seeds < 1) throw InputError("--seeds " + std::to_string(o.seeds) + ": need at least one seed");
  if (o.clamps.empty()) throw InputError("--clamps: give at least one value (0 = off)");
  for (float c : o.clamps)
    if (!(c >= 0.0f) || !std::isfinite(c)) throw InputError("--clamps: each clamp must be >= 0 (0 = off)");
  for (int d : o.max_depths)
    if (d < -1 || d > kMaxVerticesUncapped) throw InputError("--max-depths: each cap must be in [-1, 1000]");
}

}  // namespace

double one_film_bias_se(const Film& film, const Image& truth) {
  double sum_var = 0.0, n = 0.0;
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      if (!std::isfinite(truth.at(x, y).x)) continue;
      const Spectrum v = film.variance_of_mean(x, y);
      const double sd_sum = std::sqrt(double(v.x)) + std::sqrt(double(v.y)) + std::sqrt(double(v.z));
      sum_var += sd_sum * sd_sum;
      n += 3.0;
    }
  const double k = film.filter() == FilterKind::Bilinear ? 3.0 : 1.0;
  return n > 0.0 ? k * std::sqrt(sum_var) / n : 0.0;
}

SeedSpread seed_spread(const std::vector<double>& values) {
  SeedSpread s;
  if (values.empty()) return s;
  s.mean = mean(values);
  s.sd = sample_sd(values);
  s.se = s.sd / std::sqrt(static_cast<double>(values.size()));
  return s;
}

double student_two_sided_quantile(double p, int dof) {
  // P(|T| > t) = I_{dof / (dof + t^2)}(dof / 2, 1 / 2), decreasing in t:
  // bisection.
  double lo = 0.0, hi = 1e6;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (incomplete_beta(0.5 * dof, 0.5, dof / (dof + mid * mid)) > p ? lo : hi) = mid;
  }
  return hi;
}

std::vector<std::size_t> indistinguishable_from(const ConvergeResult& result, std::size_t config) {
  std::vector<std::size_t> out;
  const std::size_t budgets = [&] {
    std::size_t k = 0;
    for (const ConvergeRow& r : result.rows) k += r.config == config;
    return std::max<std::size_t>(k, 1);
  }();
  const double alpha = -std::expm1(std::log1p(-0.01) / static_cast<double>(budgets));
  for (std::size_t other = 0; other < result.configs.size(); ++other) {
    if (other == config) continue;
    bool same = true, any = false;
    for (const ConvergeRow& a : result.rows) {
      if (a.config != config) continue;
      const auto b = std::find_if(result.rows.begin(), result.rows.end(), [&](const ConvergeRow& r) {
        return r.config == other && r.time_budget == a.time_budget && r.budget == a.budget;
      });
      if (b == result.rows.end() || b->rmse_per_seed.size() != a.rmse_per_seed.size()) {
        same = false;
        break;
      }
      any = true;
      std::vector<double> diff;
      for (std::size_t s = 0; s < a.rmse_per_seed.size(); ++s) diff.push_back(a.rmse_per_seed[s] - b->rmse_per_seed[s]);
      const SeedSpread d = seed_spread(diff);
      const std::size_t R = diff.size();
      if (R < 2) {
        if (d.mean != 0.0) same = false;
        if (!same) break;
        continue;
      }
      const double t = student_two_sided_quantile(alpha, static_cast<int>(R) - 1);
      // The RMSEs; then, for spp rungs, the times (a time budget's time is
      // the budget itself, and its RMSE already carries the speed).
      const bool rmse_differs = d.sd == 0.0 ? d.mean != 0.0 : std::abs(d.mean) > t * d.se;
      const SeedSpread ta = seed_spread(a.seconds_per_seed), tb = seed_spread(b->seconds_per_seed);
      const bool time_differs =
          !a.time_budget && std::abs(ta.mean - tb.mean) > t * std::sqrt(ta.se * ta.se + tb.se * tb.se);
      if (rmse_differs || time_differs) {
        same = false;
        break;
      }
    }
    if (same && any) out.push_back(other);
  }
  return out;
}

ConvergeResult run_converge(const Scene& scene, const ConvergeOptions& options, const TracerFactory& make_tracer,
                            const std::function<void(const std::string&)>& log) {
  validate(options);
  const CompiledScene compiled{Scene(scene)};
  for (const std::string& t : options.tracers) make_tracer(t, compiled, scene.render);  // unknown names fail now
  Truth truth = find_truth(scene, options);

  ConvergeResult result;
  result.scene = scene.file.empty() ? scene.name : scene.file.string();
  result.truth = truth.description;
  result.width = scene.film.width;
  result.height = scene.film.height;
  result.seeds = options.seeds;
  result.compared_pixels = static_cast<std::size_t>(result.width) * result.height;
  if (options.exclude_emitters) {
    const std::vector<bool> mask = emitter_mask(scene, compiled, options.tracers.front(), make_tracer);
    for (std::size_t i = 0; i < mask.size(); ++i)
      if (mask[i]) {
        truth.image.pixels[i] = vec3(std::numeric_limits<float>::quiet_NaN());
        --result.compared_pixels;
      }
    if (result.compared_pixels == 0) throw InputError("--exclude-emitters: every pixel sees an emitter directly");
  }

  const std::vector<Strategy> strategies =
      options.strategies.empty() ? std::vector<Strategy>{scene.render.strategy} : options.strategies;
  const std::vector<int> depths = options.max_depths.empty() ? std::vector<int>{scene.render.max_depth} : options.max_depths;
  const std::vector<SamplerKind> samplers =
      options.samplers.empty() ? std::vector<SamplerKind>{scene.render.sampler} : options.samplers;
  const std::vector<LightSampling> light_samplings = options.light_samplings.empty()
                                                         ? std::vector<LightSampling>{scene.render.light_sampling}
                                                         : options.light_samplings;
  const std::vector<LightSamplerKind> light_samplers = options.light_samplers.empty()
                                                           ? std::vector<LightSamplerKind>{scene.render.light_sampler}
                                                           : options.light_samplers;
  for (const std::string& t : options.tracers)
    for (Strategy s : strategies)
      for (float c : options.clamps)
        for (int d : depths)
          for (SamplerKind k : samplers)
            for (LightSampling ls : light_samplings)
              for (LightSamplerKind lk : light_samplers) {
                ConvergeConfig cfg{t, s, c, d, {}, k, ls, lk};
                cfg.label = config_label(cfg, options);
                result.configs.push_back(cfg);
              }
  // The light sampler is part of the compiled scene: one per (light
  // sampling, light sampler) pair, the scene's own already made above.
  std::map<std::pair<LightSampling, LightSamplerKind>, std::unique_ptr<const CompiledScene>> recompiled;
  auto compiled_for = [&](const ConvergeConfig& cfg) -> const CompiledScene& {
    if (cfg.light_sampling == scene.render.light_sampling && cfg.light_sampler == scene.render.light_sampler)
      return compiled;
    auto& c = recompiled[{cfg.light_sampling, cfg.light_sampler}];
    if (!c) {
      Scene copy = scene;
      copy.render.light_sampling = cfg.light_sampling;
      copy.render.light_sampler = cfg.light_sampler;
      c = std::make_unique<const CompiledScene>(std::move(copy));
    }
    return *c;
  };

  const std::size_t rungs = options.spp.size(), budgets = options.time_budgets.size();
  for (std::size_t ci = 0; ci < result.configs.size(); ++ci) {
    const ConvergeConfig& cfg = result.configs[ci];
    if (log) log(cfg.label);
    std::vector<std::vector<SeedPoint>> points(rungs + budgets);
    for (int r = 0; r < options.seeds; ++r) {
      RenderSettings settings = scene.render;
      settings.strategy = cfg.strategy;
      settings.clamp = cfg.clamp;
      settings.max_depth = cfg.max_depth;
      settings.sampler = cfg.sampler;
      settings.light_sampling = cfg.light_sampling;
      settings.light_sampler = cfg.light_sampler;
      // zsobol lays each pixel's samples out for spp rounded up to a power of
      // two: the ladder's last rung makes the whole ladder one run.
      if (cfg.sampler != SamplerKind::Independent && !options.spp.empty()) settings.spp = options.spp.back();
      settings.seed = scene.render.seed + static_cast<std::uint64_t>(r);
      const auto tracer = make_tracer(cfg.tracer, compiled_for(cfg), settings);
      // The ladder: each rung extends the film of the last.
      Film film(result.width, result.height, scene.film.filter);
      double seconds = 0.0, samples = 0.0;
      std::uint32_t done = 0;
      for (std::size_t k = 0; k < rungs; ++k) {
        const auto spp = static_cast<std::uint32_t>(options.spp[k]);
        const RenderStats s = render_samples(*tracer, film, done, spp);
        done = spp;
        seconds += s.seconds;
        samples += static_cast<double>(s.samples);
        const Measure m = measure(film, truth.image);
        points[k].push_back({static_cast<double>(spp), seconds, samples, m.rmse, m.rel_mse, m.bias, m.bias_se_pixels});
      }
      // Time budgets: each from an empty film.
      for (std::size_t k = 0; k < budgets; ++k) {
        Film f(result.width, result.height, scene.film.filter);
        StopRule rule;
        rule.time_budget_seconds = options.time_budgets[k];
        const UntilResult u = render_until(*tracer, f, rule);
        const Measure m = measure(f, truth.image);
        points[rungs + k].push_back({static_cast<double>(u.spp), u.stats.seconds,
                                     static_cast<double>(u.stats.samples), m.rmse, m.rel_mse, m.bias,
                                     m.bias_se_pixels});
      }
    }
    for (std::size_t k = 0; k < rungs; ++k) result.rows.push_back(summarise(ci, false, options.spp[k], points[k]));
    for (std::size_t k = 0; k < budgets; ++k)
      result.rows.push_back(summarise(ci, true, options.time_budgets[k], points[rungs + k]));
  }
  return result;
}

namespace {

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

std::string budget_text(const ConvergeRow& r) { return r.time_budget ? fmt(r.budget) + " s" : fmt(r.budget) + " spp"; }

}  // namespace

std::string converge_csv(const ConvergeResult& result) {
  std::ostringstream out;
  out << "tracer,strategy,clamp,max_depth,budget_kind,budget,seeds,spp,seconds,samples_per_second,rmse,rmse_sd,rel_mse,"
         "bias,bias_se,efficiency,sampler,light_sampling,light_sampler\n";
  for (const ConvergeRow& r : result.rows) {
    const ConvergeConfig& c = result.configs[r.config];
    out << c.tracer << "," << strategy_name(c.strategy) << "," << fmt(c.clamp) << "," << c.max_depth << ","
        << (r.time_budget ? "time" : "spp") << "," << fmt(r.budget) << "," << r.rmse_per_seed.size() << ","
        << fmt(r.spp) << "," << fmt(r.seconds) << "," << fmt(r.samples_per_second) << "," << fmt(r.rmse) << ","
        << fmt(r.rmse_sd) << "," << fmt(r.rel_mse) << "," << fmt(r.bias) << "," << fmt(r.bias_se) << ","
        << fmt(r.efficiency) << "," << sampler_name(c.sampler) << "," << light_sampling_name(c.light_sampling) << ","
        << light_sampler_name(c.light_sampler) << "\n";
  }
  return out.str();
}

std::string converge_markdown(const ConvergeResult& result) {
  std::ostringstream out;
  out << "# pathlab converge: " << result.scene << "\n\n"
      << "Ground truth: " << result.truth << ". " << result.width << "x" << result.height << ", "
      << result.compared_pixels << " pixels compared, " << result.seeds << " seed(s) per budget.\n\n"
      << "| configuration | budget | spp | time (s) | samples/s | RMSE | ± sd | relMSE | bias ± se | efficiency |\n"
      << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const ConvergeRow& r : result.rows)
    out << "| " << result.configs[r.config].label << " | " << budget_text(r) << " | " << fmt(r.spp) << " | "
        << fmt(r.seconds) << " | " << fmt(r.samples_per_second) << " | " << fmt(r.rmse) << " | " << fmt(r.rmse_sd)
        << " | " << fmt(r.rel_mse) << " | " << fmt(r.bias) << " ± " << fmt(r.bias_se) << " | " << fmt(r.efficiency)
        << " |\n";
  const double target = default_target_rmse(result);
  std::string first = first_to_reach_text(result, target);
  first[0] = 'F';
  out << "\n" << first << ".\n";
  return out.str();
}

std::string first_to_reach_text(const ConvergeResult& result, double target_rmse) {
  const auto first = first_to_reach(result, target_rmse);
  if (!first) return "no configuration reached RMSE " + fmt(target_rmse) + " within its budgets";
  const std::string when = std::string(first->at_first_budget ? "at most " : "about ") + fmt(first->seconds) + " s" +
                           (first->at_first_budget ? " (already at its first budget)" : "");
  const std::vector<std::size_t> same = indistinguishable_from(result, first->config);
  if (same.empty())
    return "first to reach RMSE " + fmt(target_rmse) + ": **" + result.configs[first->config].label + "**, in " + when;
  std::string names = result.configs[first->config].label;
  for (std::size_t c : same) names += ", " + result.configs[c].label;
  return "first to reach RMSE " + fmt(target_rmse) + ": no winner among **" + names +
         "**, statistically indistinguishable (" +
         (result.seeds >= 2 ? "RMSE and time within the seeds' spread at every budget"
                            : "the same RMSE at every budget; one seed cannot judge their times") +
         "); the first of them in " + when;
}

namespace {

// A configuration's rows as (x, mean RMSE) points sorted by x.
std::vector<std::pair<double, double>> curve(const ConvergeResult& result, std::size_t config, bool by_time) {
  std::vector<std::pair<double, double>> pts;
  for (const ConvergeRow& r : result.rows)
    if (r.config == config) pts.emplace_back(by_time ? r.seconds : r.spp, r.rmse);
  std::sort(pts.begin(), pts.end());
  return pts;
}

}  // namespace

double default_target_rmse(const ConvergeResult& result) {
  double target = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < result.configs.size(); ++c) {
    const auto pts = curve(result, c, true);
    if (!pts.empty()) target = std::min(target, pts.front().second);
  }
  return target;
}

std::optional<FirstToReach> first_to_reach(const ConvergeResult& result, double target_rmse) {
  std::optional<FirstToReach> best;
  for (std::size_t c = 0; c < result.configs.size(); ++c) {
    const auto pts = curve(result, c, true);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (pts[i].second > target_rmse) continue;
      double t = pts[i].first;
      if (i > 0 && pts[i - 1].second > target_rmse && pts[i - 1].first > 0.0 && t > 0.0) {
        // Log-log interpolation between the last point above and this one.
        const double a = std::log(pts[i - 1].second / target_rmse) / std::log(pts[i - 1].second / pts[i].second);
        t = std::exp(std::log(pts[i - 1].first) + a * std::log(t / pts[i - 1].first));
      }
      if (!best || t < best->seconds) best = FirstToReach{c, t, i == 0};
      break;
    }
  }
  return best;
}

double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
    if (!(x[i] > 0.0) || !(y[i] > 0.0)) continue;
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    n += 1;
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  const double d = n * sxx - sx * sx;
  return d > 0.0 ? (n * sxy - sx * sy) / d : std::numeric_limits<double>::quiet_NaN();
}

void write_converge_report(const std::filesystem::path& dir, const ConvergeResult& result) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const auto write_text = [&](const std::string& name, const std::string& text) {
    write_via_temp_file(dir / name, name, [&](const std::filesystem::path& temp) {
      std::ofstream f(temp, std::ios::binary);
      f << text;
      f.close();
      if (!f) throw SystemError((dir / name).string() + ": cannot write");
    });
  };
  const std::string name = std::filesystem::path(result.scene).filename().string();
  LogLogPlot by_time{"RMSE against wall time: " + name, "wall time (s)", "RMSE", {}, 0.0, ""};
  LogLogPlot by_spp{"RMSE against samples per pixel: " + name, "samples per pixel", "RMSE", {}, -0.5,
                    "slope -1/2 (Monte Carlo rate)"};
  for (std::size_t c = 0; c < result.configs.size(); ++c) {
    PlotSeries t{result.configs[c].label, {}, {}}, s{result.configs[c].label, {}, {}};
    for (const auto& [x, y] : curve(result, c, true)) t.x.push_back(x), t.y.push_back(y);
    for (const auto& [x, y] : curve(result, c, false)) s.x.push_back(x), s.y.push_back(y);
    by_time.series.push_back(std::move(t));
    by_spp.series.push_back(std::move(s));
  }
  // Build everything before writing anything.
  const std::string csv = converge_csv(result), md = converge_markdown(result);
  const std::string svg_time = loglog_svg(by_time), svg_spp = loglog_svg(by_spp);
  write_text("converge.csv", csv);
  write_text("converge.md", md);
  write_text("rmse-vs-time.svg", svg_time);
  write_text("rmse-vs-spp.svg", svg_spp);
}

}  // namespace pathlab
