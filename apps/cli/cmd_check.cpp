// pathlab check SCENE [--tracer T] [--strategy S] [--spp N] [--seed S] [--out DIR]
// Renders an analytic scene, computes its expected image and decides with
// statistics whether they agree (analytic-scenes/check.h). Exit 0 pass,
// 1 fail, 2 bad input.
#include "apps/cli/commands.h"
#include "apps/cli/validators.h"

#include "analytic-scenes/check.h"
#include "analytic-scenes/expected_image.h"
#include "apps/cli/progress.h"
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/render.h"

#include <cstdio>
#include <ostream>

namespace pathlab::cli {

void CheckCommand::add_to(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("check", "Render an analytic scene and test it against its closed-form image");
  scene.add_to(*cmd, true);
  cmd->add_option("--out", out_dir, "Folder for the rendered, expected, error and z-score EXRs on failure; "
                                    "default out/check-<scene>");
  cmd->add_option("--threads", threads, "Worker threads (0 = all)")->check(CLI::Range(0, 4096));
  cmd->add_option("--alpha", alpha, "Family-wise false-alarm rate of the tests")->check(number_range(1e-12, 0.5));
  cmd->callback([this] { selected = true; });
}

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace

int CheckCommand::run(std::ostream& /*out*/, std::ostream& err) const {
  if (scene.scene_file.empty()) throw InputError("check needs a scene file with an \"analytic\" model, e.g. analytic-scenes/furnace-sphere.json");
  Scene s = scene.load();
  for (const std::string& w : s.warnings) err << "pathlab: warning: " << w << "\n";
  const auto model = make_analytic_model(s);  // refuses a scene that breaks the model's assumptions
  const std::filesystem::path dir = out_dir.empty() ? std::filesystem::path("out") / ("check-" + s.name) : std::filesystem::path(out_dir);

  const ThreadLimit limit(threads);
  const RenderSettings settings = s.render;
  const CompiledScene compiled(std::move(s));
  const Scene& sc = compiled.scene();
  const auto tracer = make_tracer(scene.tracer, compiled, settings);
  Film film(sc.film.width, sc.film.height, sc.film.filter);
  ProgressBar bar(err, "rendering", stderr_is_terminal());
  const RenderStats stats = render(*tracer, film, [&](double f) { bar.update(f); });
  bar.finish();
  const ExpectedImage expected = expected_image(*model, compiled.camera(), sc.film);
  CheckOptions options;
  options.alpha = alpha;
  const CheckResult r = check_against_expected(film, expected, options);

  const char* channel = "RGB";
  err << "pathlab check: " << sc.file.string() << ": " << model->name() << ": " << model->describe() << "\n"
      << "  " << tracer->name() << " tracer, " << strategy_name(settings.strategy) << ", " << settings.spp
      << " spp, seed " << settings.seed << ", " << sc.film.width << "x" << sc.film.height << " "
      << (sc.film.filter == FilterKind::Box ? "box" : "bilinear") << " (" << fmt("%.2f", stats.seconds) << " s)\n"
      << "  " << (r.pass ? "PASS" : "FAIL") << "  pixels: " << r.failing << " of " << 3 * sc.film.width * sc.film.height
      << " pixel-channels beyond |z| " << fmt("%.2f", r.z_threshold) << " (Sidak, alpha " << alpha << "), worst |z| "
      << fmt("%.2f", r.worst.empty() ? 0.0 : std::abs(r.worst.front().z)) << "\n"
      << "        bias (" << channel[r.bias_channel] << ", the most significant channel) " << fmt("%.3g", r.bias) << " +- " << fmt("%.2g", r.bias_se) << " (z " << fmt("%.2f", r.bias_z)
      << ", threshold " << fmt("%.2f", r.bias_threshold) << ")" << (r.bias_pass ? "" : "  <- biased") << "\n"
      << "        RMSE " << fmt("%.3g", r.rmse) << ", relative MSE " << fmt("%.3g", r.rel_mse) << "\n";
  if (stats.bad_samples > 0) err << "  " << stats.bad_samples << " NaN/Inf sample(s) left out of the image\n";
  if (settings.clamp > 0.0f || settings.min_pdf > 0.0f) {
    // Firefly controls trade bias for variance: report the bias they
    // introduce instead of passing or failing silently.
    double rendered = 0.0, wanted = 0.0;
    for (int y = 0; y < sc.film.height; ++y)
      for (int x = 0; x < sc.film.width; ++x) {
        rendered += average(film.mean(x, y));
        wanted += average(expected.mean.at(x, y));
      }
    err << "  firefly controls on (clamp " << settings.clamp << ", min-pdf " << settings.min_pdf
        << "): this check measures their bias, it does not test unbiasedness\n";
    if (settings.clamp > 0.0f)
      err << "    clamp: " << stats.clamped_samples << " of " << stats.samples << " samples clamped ("
          << fmt("%.3g", 100.0 * static_cast<double>(stats.clamped_samples) / static_cast<double>(std::max<std::uint64_t>(stats.samples, 1)))
          << " %), relative energy removed " << fmt("%.3g", stats.relative_energy_clamped())
          << "\n";
    err << "    measured bias vs the analytic image: " << fmt("%+.3g", wanted > 0.0 ? rendered / wanted - 1.0 : 0.0)
        << " relative (mean over the image)\n";
  }
  err << "  worst pixels:\n";
  for (const PixelDeviation& p : r.worst)
    err << "    (" << p.x << ", " << p.y << ") " << channel[p.channel] << ": rendered " << fmt("%.5g", p.rendered)
        << ", expected " << fmt("%.5g", p.expected) << " +- " << fmt("%.2g", p.sigma) << ", z " << fmt("%.2f", p.z)
        << "\n      " << scene.trace_pixel_command(sc, static_cast<std::uint32_t>(p.x), static_cast<std::uint32_t>(p.y), 0)
        << "\n";
  if (!r.worst.empty()) {
    const PixelDeviation& p = r.worst.front();
    if (std::abs(p.z) > r.z_threshold && film.variance_of_mean(p.x, p.y)[p.channel] == 0.0f)
      err << "  note: the worst pixel's samples were all equal, so its variance is unknown rather than zero (a light "
             "found too rarely at this sample count?); try more --spp before suspecting the tracer\n";
  }
  if (!r.pass) {
    const ImageMetadata meta = {{"scene", sc.file.string()}, {"model", std::string(model->name())},
                                {"tracer", std::string(tracer->name())}, {"strategy", strategy_name(settings.strategy)},
                                {"spp", std::to_string(settings.spp)}, {"seed", std::to_string(settings.seed)}};
    write_check_images(dir, film, expected, r, meta);
    err << "  wrote rendered.exr, expected.exr, error.exr and zscore.exr to " << dir.string() << "\n";
  }
  return r.pass ? 0 : 1;
}

}  // namespace pathlab::cli
