// pathlab render [SCENE] [-o out.exr] [--tracer T] [--strategy S] [--spp N]
//                [--max-depth D] [--rr-depth R] [--seed S] [--threads T]
//                [--resolution WxH] [--aov albedo,normal,...] [--quiet]
//                [--time SECONDS] [--target-relmse X]   (progressive: --spp is then the most it renders)
#include "apps/cli/commands.h"

#include "apps/cli/progress.h"
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/parallel.h"
#include "core/render.h"
#include "debugtools/aov.h"
#include "wavefront/wavefront_tracer.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <optional>
#include <ostream>

namespace pathlab::cli {

void RenderCommand::add_to(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("render", "Render a scene to EXR and PNG");
  scene.add_to(*cmd, true);
  cmd->add_option("-o,--output", output, "Output EXR (a tone-mapped PNG is written beside it); default out/<scene>.exr");
  std::vector<std::string> aov_names;
  for (Aov a : kAllAovs) aov_names.emplace_back(aov_name(a));
  cmd->add_option("--aov", aovs, "Extra EXR layers, comma-separated: albedo, normal, depth, material, variance, pathlength")
      ->delimiter(',')
      ->check(CLI::IsMember(aov_names));
  cmd->add_option("--threads", threads, "Worker threads (0 = all)")->check(CLI::Range(0, 4096));
  cmd->add_option("--exposure", exposure, "Exposure of the PNG, in stops");
  cmd->add_option("--time", time_budget, "Stop at this wall-clock budget (whole passes); --spp is then a cap")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--target-relmse", target_relmse,
                  "Stop when the relative MSE estimated from per-pixel variance falls below X; --spp is then a cap")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("-q,--quiet", quiet, "Print only warnings and errors");
  cmd->callback([this] { selected = true; });
}

int RenderCommand::run(std::ostream& /*out*/, std::ostream& err) const {
  Scene s = scene.load();
  for (const std::string& w : s.warnings) err << "pathlab: warning: " << w << "\n";

  std::filesystem::path exr = output.empty() ? std::filesystem::path("out") / (s.name + ".exr") : std::filesystem::path(output);
  std::string ext = exr.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".exr") throw InputError(exr.string() + ": the output must be an .exr file (a .png is written beside it)");
  std::filesystem::path png = exr;
  png.replace_extension(".png");
  ensure_writable(exr);
  ensure_writable(png);

  const ThreadLimit limit(threads);
  const RenderSettings settings = s.render;
  const CompiledScene compiled(std::move(s));
  const auto tracer = make_tracer(scene.tracer, compiled, settings);
  // With --aov the driver renders through a tracer that also fills the AOVs.
  std::vector<Aov> layers;
  for (const std::string& name : aovs) layers.push_back(*parse_aov(name));
  std::optional<AovAccumulator> aov_buffers;
  std::optional<AovTracer> aov_tracer;
  if (!layers.empty()) {
    aov_buffers.emplace(compiled, settings);
    aov_tracer.emplace(*tracer, *aov_buffers);
  }
  const Scene& sc = compiled.scene();
  if (const std::size_t n = compiled.lights().unsampled_light_count())
    err << "pathlab: warning: " << n << " light(s) are too dim next to the others ever to be picked for light "
        << "sampling; only rays that hit them count their light\n";
  const bool progressive = time_budget || target_relmse;
  // The second moments only if something reads them: progressive rendering
  // estimates its error from them, and the variance AOV is them.
  const bool variance = progressive || std::find(layers.begin(), layers.end(), Aov::Variance) != layers.end();
  Film film(sc.film.width, sc.film.height, sc.film.filter, variance ? FilmMoments::MeanAndVariance : FilmMoments::Mean);

  ProgressBar bar(err, "rendering", !quiet && stderr_is_terminal());
  const Tracer& driven = aov_tracer ? static_cast<const Tracer&>(*aov_tracer) : *tracer;
  std::optional<UntilResult> until;
  if (progressive) {
    // Without an explicit --spp the budget or target decides alone.
    until = render_until(driven, film, {time_budget.value_or(0.0), target_relmse.value_or(0.0),
                                        scene.spp ? settings.spp : 1 << 24, 0},
                         [&](double f) { bar.update(f); });
  }
  const RenderStats stats = progressive ? until->stats : render(driven, film, [&](double f) { bar.update(f); });
  const int spp_done = progressive ? static_cast<int>(until->spp) : settings.spp;
  bar.finish();

  const Image image = film.image();
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.3f", stats.seconds);
  ImageMetadata meta = {
      {"scene", sc.file.empty() ? "<built-in " + sc.name + ">" : sc.file.string()},
      {"tracer", std::string(tracer->name())},
      {"strategy", strategy_name(settings.strategy)},
      {"spp", std::to_string(spp_done)},
      {"seed", std::to_string(settings.seed)},
      {"max_depth", std::to_string(settings.max_depth)},
      {"rr_depth", std::to_string(settings.rr_depth)},
      {"filter", sc.film.filter == FilterKind::Box ? "box" : "bilinear"},
      {"render_time_seconds", seconds},
      {"bad_samples", std::to_string(stats.bad_samples)},
      {"version", PATHLAB_VERSION},
  };
  if (progressive) {
    char relmse[32];
    std::snprintf(relmse, sizeof relmse, "%.6g", until->estimated_relmse);
    meta.emplace_back("spp_reached", std::to_string(spp_done));
    meta.emplace_back("estimated_relmse", relmse);
    if (time_budget) meta.emplace_back("time_budget_seconds", std::to_string(*time_budget));
    if (target_relmse) meta.emplace_back("target_relmse", std::to_string(*target_relmse));
  }
  if (layers.empty()) write_exr(exr, image, meta);
  else write_exr_channels(exr, film.width(), film.height(), aov_channels(film, *aov_buffers, layers), meta);
  try {
    write_png(png, image, exposure);
  } catch (...) {
    // The two files are one result: do not leave the EXR without its PNG.
    std::error_code ignored;
    std::filesystem::remove(exr, ignored);
    throw;
  }

  if (stats.bad_samples > 0) {
    err << "pathlab: warning: " << stats.bad_samples
        << " sample(s) had NaN or infinite radiance and were left out of the image. Replay them with:\n";
    for (const BadSample& b : film.bad_samples())
      err << "  " << scene.trace_pixel_command(sc, b.x, b.y, b.sample) << "\n";
  }
  if (!quiet) {
    char line[256];
    std::snprintf(line, sizeof line, "%.2f s, %.3g samples/s, %.3g rays/s", stats.seconds,
                  static_cast<double>(stats.samples) / std::max(stats.seconds, 1e-9),
                  static_cast<double>(stats.rays) / std::max(stats.seconds, 1e-9));
    err << "pathlab: wrote " << exr.string() << " and " << png.string() << " (" << sc.film.width << "x"
        << sc.film.height << ", " << spp_done << " spp, " << tracer->name() << ", "
        << strategy_name(settings.strategy) << "): " << line << "\n";
    if (const auto* wf = dynamic_cast<const WavefrontTracer*>(tracer.get())) {
      err << "pathlab: wavefront: one wave of up to " << wf->wave_size() << " paths per thread, "
          << wf->bytes_per_path() << " bytes of path state per path ("
          << (wf->wave_size() * wf->bytes_per_path() * static_cast<std::size_t>(max_threads()) + 512 * 1024) /
                 (1024 * 1024)
          << " MiB in flight on " << max_threads() << " threads); "
          << wf->stages_description() << "; rays to Embree: camera " << ray_batch_mode_name(wf->ray_modes().camera)
          << ", bounce " << ray_batch_mode_name(wf->ray_modes().bounce) << ", shadow "
          << ray_batch_mode_name(wf->ray_modes().shadow) << "\n";
      if (const WavefrontTimes t = wf->times(); t.waves_seconds > 0.0) {
        std::snprintf(line, sizeof line,
                      "%.0f%% of the waves' time in Embree; per thread, camera %.3g, bounce %.3g, shadow %.3g rays/s",
                      100.0 * t.query_seconds() / t.waves_seconds, t.camera.rays_per_second(),
                      t.bounce.rays_per_second(), t.shadow.rays_per_second());
        err << "pathlab: wavefront: " << line << "\n";
      }
    }
  }
  return 0;
}

}  // namespace pathlab::cli
