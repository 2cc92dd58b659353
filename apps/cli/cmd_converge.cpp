// pathlab converge SCENE [--reference ref.exr] [--tracers T,...] [--strategies S,...]
//                  [--spp 1,4,16,...] [--time-budgets SEC,...] [--seeds R] [--clamps C,...]
//                  [--max-depths D,...] [--sampler K | --samplers A,B] [--light-samplings A,B] [--light-samplers A,B]
//                  [--exclude-emitters] [--target-rmse X] [--threads N] --out DIR
#include "apps/cli/commands.h"
#include "apps/cli/validators.h"

#include "core/error.h"
#include "core/image_io.h"
#include "core/parallel.h"
#include "core/scene_loader.h"
#include "core/tracer.h"
#include "debugtools/converge.h"

#include <string>
#include <ostream>

namespace pathlab::cli {

void ConvergeCommand::add_to(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("converge", "Speed-accuracy sweep: error against time and spp, table and plots");
  cmd->add_option("scene", scene_file, "Scene file (JSON)")->required();
  cmd->add_option("--reference", reference, "Ground-truth EXR (default: the scene's analytic expected image)");
  cmd->add_option("--tracers", options.tracers, "Tracers, comma-separated: reference, wavefront (default: both)")->delimiter(',');
  cmd->add_option("--strategies", strategies, "Strategies, comma-separated (default: all five)")->delimiter(',');
  CLI::Option* one_sampler =
      cmd->add_option("--sampler", sampler, "Sampler of every render: independent or zsobol (default: both, compared)")
          ->check(CLI::IsMember({"independent", "zsobol"}));
  cmd->add_option("--samplers", samplers, "Samplers to compare, comma-separated: independent, zsobol (default: both)")
      ->delimiter(',')
      ->check(CLI::IsMember({"independent", "zsobol"}))
      ->excludes(one_sampler);
  cmd->add_option("--light-samplings", light_samplings,
                  "How to sample a point on an area light, comma-separated: area, solid_angle (default: the scene's)")
      ->delimiter(',')
      ->check(CLI::IsMember({"area", "solid_angle"}));
  cmd->add_option("--light-samplers", light_samplers,
                  "How to pick an area light, comma-separated: power, bvh (default: the scene's)")
      ->delimiter(',')
      ->check(CLI::IsMember({"power", "bvh"}));
  cmd->add_option("--spp", options.spp, "The samples-per-pixel ladder, increasing, comma-separated")
      ->delimiter(',')
      ->check(CLI::Range(1, 1 << 24));
  cmd->add_option("--time-budgets", options.time_budgets, "Wall-clock budgets in seconds, comma-separated")
      ->delimiter(',')
      ->check(positive_number());
  cmd->add_option("--seeds", options.seeds, "Independent seeds per budget (R)")->check(CLI::Range(1, 1000));
  cmd->add_option("--clamps", options.clamps, "Radiance clamps to compare, comma-separated (0 = off)")
      ->delimiter(',')
      ->check(number_range(0.0, 3.4e38));
  cmd->add_option("--max-depths", options.max_depths, "Depth caps to compare against the uncapped answer, comma-separated")
      ->delimiter(',');
  cmd->add_flag("--exclude-emitters", options.exclude_emitters, "Leave out pixels that see an emitter directly");
  cmd->add_option("--target-rmse", target_rmse, "Report which configuration reaches this RMSE first")
      ->check(positive_number());
  cmd->add_option("--resolution", resolution, "Image size WxH (the reference EXR must match it)");
  cmd->add_option("--threads", threads, "Worker threads (0 = all)")->check(CLI::Range(0, 4096));
  cmd->add_option("--out", out_dir, "Folder for converge.csv, converge.md and the SVG plots")->required();
  cmd->callback([this] { selected = true; });
}

int ConvergeCommand::run(std::ostream& /*out*/, std::ostream& err) const {
  ConvergeOptions o = options;
  o.reference = reference;
  if (!strategies.empty()) o.strategies.clear();
  for (const std::string& s : strategies) {
    const auto st = parse_strategy(s);
    if (!st) throw InputError("--strategies: unknown strategy '" + s + "' (expected cosine, bsdf, light, light+bsdf or mis)");
    o.strategies.push_back(*st);
  }
  if (!samplers.empty()) o.samplers.clear();
  for (const std::string& s : samplers) o.samplers.push_back(*parse_sampler(s));  // checked by CLI11
  if (sampler) o.samplers = {*parse_sampler(*sampler)};
  for (const std::string& s : light_samplings) o.light_samplings.push_back(*parse_light_sampling(s));  // checked by CLI11
  for (const std::string& s : light_samplers) o.light_samplers.push_back(*parse_light_sampler(s));     // checked by CLI11
  // Fail on an unwritable folder now, not after the sweep; on any failure
  // remove the folder again if this run made it and it is still empty.
  const std::filesystem::path dir(out_dir);
  const bool existed = std::filesystem::exists(dir);
  ConvergeResult result;
  try {
    ensure_writable(dir / "converge.csv");
    Scene scene = load_scene(scene_file);
    if (resolution) apply_resolution(*resolution, scene.film);
    if (sampler) scene.render.sampler = *parse_sampler(*sampler);
    for (const std::string& w : scene.warnings) err << "pathlab: warning: " << w << "\n";
    const ThreadLimit limit(threads);
    result = run_converge(scene, o, make_tracer,
                          [&](const std::string& line) { err << "pathlab: converge: " << line << "\n"; });
    write_converge_report(dir, result);
  } catch (...) {
    std::error_code ignored;
    if (!existed && std::filesystem::is_empty(dir, ignored)) std::filesystem::remove(dir, ignored);
    throw;
  }

  const double target = target_rmse.value_or(default_target_rmse(result));
  std::string first = first_to_reach_text(result, target);
  std::erase(first, '*');
  err << "pathlab: converge: " << first << "\n";
  err
      << "pathlab: wrote " << (dir / "converge.csv").string()
      << ", converge.md, rmse-vs-time.svg and rmse-vs-spp.svg (truth: "
      << result.truth << ")\n";
  return 0;
}

}  // namespace pathlab::cli
