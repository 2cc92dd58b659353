// pathlab render [SCENE] [-o out.exr] [--tracer T] [--strategy S] [--spp N]
//                [--max-depth D] [--rr-depth R] [--seed S] [--threads T]
//                [--resolution WxH] [--aov albedo,normal,...] [--quiet]
//                [--time SECONDS] [--target-relmse X]   (progressive: --spp is then the most it renders)
//                [--checkpoint FILE [--checkpoint-every S]] [--resume FILE] [--passes A..B]
//                (-o part.pfilm writes the partial film instead of an image: docs/overnight.md)
#include "apps/cli/commands.h"
#include "apps/cli/validators.h"

#include "apps/cli/interrupt.h"
#include "apps/cli/progress.h"
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/limits.h"
#include "core/partial_film.h"
#include "core/parallel.h"
#include "core/render.h"
#include "core/scene_limits.h"
#include "core/simd/simd.h"
#include "debugtools/aov.h"
#include "debugtools/bounce_aov.h"
#include "debugtools/stage_buffers.h"
#include "distributed/mpi_job.h"
#include "wavefront/wavefront_tracer.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <optional>
#include <ostream>

namespace pathlab::cli {

std::string shell_command_line(int argc, const char* const* argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    const std::string word = argv[i] != nullptr ? argv[i] : "";
    const bool plain = !word.empty() && word.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                                               "0123456789_@%+=:,./-") == std::string::npos;
    if (i > 0) line += ' ';
    if (plain) {
      line += word;
      continue;
    }
    line += '\'';
    for (char c : word) line += c == '\'' ? std::string("'\\''") : std::string(1, c);
    line += '\'';
  }
  return line;
}

void RenderCommand::add_to(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("render", "Render a scene to EXR and PNG");
  scene.add_to(*cmd, true);
  cmd->add_option("-o,--output", output, "Output EXR (a tone-mapped PNG is written beside it); default out/<scene>.exr");
  std::vector<std::string> aov_names;
  for (Aov a : kAllAovs) aov_names.emplace_back(aov_name(a));
  cmd->add_option("--aov", aovs,
                  "Extra EXR layers, comma-separated: albedo, normal, depth, material, variance, pathlength, bounces "
                  "(radiance per path depth L0..L7 and rest, by technique bsdf / nee)")
      ->delimiter(',')
      ->check(CLI::IsMember(aov_names));
  cmd->add_option("--threads", threads, "Worker threads (0 = all)")->check(CLI::Range(0, 4096));
  cmd->add_option("--exposure", exposure, "Exposure of the PNG, in stops")->check(number_range(-64.0, 64.0));
  cmd->add_option("--time", time_budget, "Stop at this wall-clock budget (whole passes); --spp is then a cap")
      ->check(positive_number());
  cmd->add_option("--target-relmse", target_relmse,
                  "Stop when the relative MSE estimated from per-pixel variance falls below X; --spp is then a cap")
      ->check(positive_number());
  cmd->add_option("--checkpoint", checkpoint,
                  "Keep the render's state in FILE (a partial film), rewritten atomically every --checkpoint-every "
                  "seconds, on Ctrl-C / SIGTERM and at the end; --resume FILE goes on from it");
  cmd->add_option("--checkpoint-every", checkpoint_every, "Seconds between checkpoints (default 600)")
      ->check(positive_number());
  cmd->add_option("--resume", resume, "Go on from this checkpoint (same scene, files and settings) to the same bits");
  cmd->add_option("--passes", passes,
                  "Render only sample passes A..B (sample indices A to B-1 of every pixel); with -o X.pfilm the "
                  "partial film is written for 'pathlab merge'");
  cmd->add_option("--dump-stage-buffers", stage_buffers,
                  "Wavefront only: write its per-path arrays at bounce K (vertex K; 1 = the camera rays' hits) "
                  "splatted to images, DIR/bounceK-<array>.exr (docs/aov.md)")
      ->expected(2)
      ->type_name("K DIR");
  cmd->add_flag("-q,--quiet", quiet, "Print only warnings and errors");
  cmd->callback([this] { selected = true; });
}

namespace {

// "A..B" -> [A, B).
PassRange parse_passes(const std::string& text) {
  const std::size_t dots = text.find("..");
  const auto number = [&](const std::string& part) -> std::optional<std::uint32_t> {
    if (part.empty() || part.size() > 9 || part.find_first_not_of("0123456789") != std::string::npos) return {};
    return static_cast<std::uint32_t>(std::stoul(part));
  };
  const auto a = dots == std::string::npos ? std::nullopt : number(text.substr(0, dots));
  const auto b = dots == std::string::npos ? std::nullopt : number(text.substr(dots + 2));
  if (!a || !b || *b <= *a)
    throw InputError("--passes " + text + ": expected A..B with 0 <= A < B (sample passes A to B-1), e.g. 0..64");
  return {*a, *b};
}

}  // namespace

int RenderCommand::run(std::ostream& /*out*/, std::ostream& err) const {
  // Under mpirun: one render over every rank (distributed/mpi_job.h).
  const MpiJob job;
  const bool chatty = job.rank() == 0;  // the other ranks say nothing but errors
  Scene s = scene.load();
  if (chatty)
    for (const std::string& w : s.warnings) err << "pathlab: warning: " << w << "\n";

  std::filesystem::path exr = output.empty() ? std::filesystem::path("out") / (s.name + ".exr") : std::filesystem::path(output);
  // -o X.pfilm: the partial film itself, for `pathlab merge`, and no image.
  const bool partial_output = lower_extension(exr) == ".pfilm";
  if (!partial_output && lower_extension(exr) != ".exr")
    throw InputError(exr.string() + ": the output must be an .exr file (a .png is written beside it), or a .pfilm "
                     "partial film");
  std::filesystem::path png = exr;
  png.replace_extension(".png");
  if (chatty) {
    ensure_writable(exr);
    if (!partial_output) ensure_writable(png);
    if (checkpoint) ensure_writable(*checkpoint);
  }

  const bool progressive = time_budget || target_relmse;
  std::vector<Aov> layers;
  for (const std::string& name : aovs) layers.push_back(*parse_aov(name));
  const bool variance_aov = std::find(layers.begin(), layers.end(), Aov::Variance) != layers.end();
  const bool pieces = checkpoint || resume || passes || partial_output;
  if (pieces && std::any_of(layers.begin(), layers.end(), [](Aov a) { return a != Aov::Variance; }))
    throw InputError("--aov: only the variance layer is kept in a partial film; the others cannot go with "
                     "--checkpoint, --resume, --passes or a .pfilm output yet");
  if (partial_output && !layers.empty()) throw InputError("--aov: a .pfilm output holds no image layers");
  const bool bounces_aov = std::find(layers.begin(), layers.end(), Aov::Bounces) != layers.end();
  if (bounces_aov && s.render.clamp > 0.0f)
    throw InputError("--aov bounces: the layers hold each sample's unclamped radiance, so with --clamp they would not "
                     "sum to the image; render them without --clamp");
  std::optional<int> stage_vertex;
  std::filesystem::path stage_dir;
  if (!stage_buffers.empty()) {
    int k = 0;
    const std::string& text = stage_buffers[0];
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), k);
    if (ec != std::errc() || ptr != text.data() + text.size() || k < 1 || k > kMaxVerticesUncapped)
      throw InputError("--dump-stage-buffers " + text + ": K must be a vertex number in [1, " +
                       std::to_string(kMaxVerticesUncapped) + "] (1 = the camera rays' hits)");
    if (scene.tracer != "wavefront")
      throw InputError("--dump-stage-buffers: the stage buffers are the wavefront's; add --tracer wavefront");
    if (pieces || progressive || job.distributed() || bounces_aov)
      throw InputError("--dump-stage-buffers goes with a plain render: not with --checkpoint, --resume, --passes, a "
                       ".pfilm output, --time, --target-relmse, mpirun or --aov bounces");
    stage_vertex = k;
    stage_dir = stage_buffers[1];
    std::error_code dir_error;  // refused before rendering, not after
    std::filesystem::create_directories(stage_dir, dir_error);
    if (dir_error || !std::filesystem::is_directory(stage_dir))
      throw InputError("--dump-stage-buffers: " + stage_dir.string() + ": cannot create the folder" +
                       (dir_error ? ": " + dir_error.message() : std::string()));
  }
  if (passes && progressive) throw InputError("--passes renders a fixed range of passes; --time and --target-relmse cannot go with it");
  if (job.distributed() && progressive)
    throw InputError("--time and --target-relmse are not supported under mpirun yet; give --spp");
  if (job.distributed() && !layers.empty())
    throw InputError("--aov is not supported under mpirun yet (the AOV buffers are not reduced over ranks)");
  // The film and what is written from it, before anything is allocated or a
  // folder made (core/limits.h): per pixel the film's sums (56 bytes), its
  // second moments (48) when kept, a splatting filter's sums (80), the image
  // and its PNG (15), and each AOV's buffer and channels (64), but `bounces`:
  // per layer and technique its sums and, written, a mean and a variance
  // image and their float channels (about 1.7 kB).
  {
    const bool moments = progressive || variance_aov;
    constexpr std::uint64_t kBouncesPerPixel =
        sizeof(std::uint64_t) + std::uint64_t{kBounceLayers} * kTechniques * (sizeof(BounceAccumulator::Sums) + 4 * sizeof(vec3));
    const std::uint64_t per_pixel = 56 + (moments ? 48 : 0) + (s.film.filter == FilterKind::Box ? 0 : 80) + 15 +
                                    64 * static_cast<std::uint64_t>(layers.size() - (bounces_aov ? 1 : 0)) +
                                    (bounces_aov ? kBouncesPerPixel : 0);
    check_memory(static_cast<std::uint64_t>(s.film.width) * static_cast<std::uint64_t>(s.film.height) * per_pixel,
                 "the " + std::to_string(s.film.width) + "x" + std::to_string(s.film.height) + " film" +
                     (layers.empty() ? std::string() : " with " + std::to_string(layers.size()) + " AOV(s)"));
  }
  const std::uint32_t spp = static_cast<std::uint32_t>(std::max(s.render.spp, 0));
  const PassRange range = passes ? parse_passes(*passes) : PassRange{0, spp};

  // The fingerprint and the checkpoint are read before the scene is compiled,
  // so that a mismatch is reported at once.
  const Fingerprint fingerprint = render_fingerprint(s, scene.tracer);
  std::optional<PartialFilm> resumed;
  if (resume) {
    resumed = read_partial_film(*resume);
    const PartialFilmInfo& was = resumed->info;
    if (!(was.fingerprint == fingerprint))
      throw InputError(*resume + ": a checkpoint of another render; what differs:\n" +
                       fingerprint_difference(was.fingerprint, fingerprint, "checkpoint", "this render"));
    if (was.passes.begin != range.begin)
      throw InputError(*resume + ": it holds passes " + std::to_string(was.passes.begin) + ".." +
                       std::to_string(was.passes.end) + ", not a start of passes " + std::to_string(range.begin) +
                       ".." + std::to_string(range.end));
    if (!progressive && was.passes.end > range.end)
      throw InputError(*resume + ": it already holds passes " + std::to_string(was.passes.begin) + ".." +
                       std::to_string(was.passes.end) + ", beyond the " + std::to_string(range.end) +
                       " asked for (--spp or --passes)");
    const bool needs_variance = progressive || variance_aov;
    if (needs_variance && !resumed->film.keeps_variance())
      throw InputError(*resume + ": its film keeps no variance, which " +
                       (progressive ? std::string("--time and --target-relmse need") : std::string("--aov variance is")));
  }

  const ThreadLimit limit(threads);
  const RenderSettings settings = s.render;
  const CompiledScene compiled(std::move(s));
  const auto tracer = make_tracer(scene.tracer, compiled, settings);
  // With --aov the driver renders through a tracer that also fills the AOVs
  // (and, for `bounces`, one that traces every sample with an observer);
  // with --dump-stage-buffers through one that records the wavefront's
  // arrays. Without them the driver renders the tracer itself.
  const Tracer* inner = tracer.get();
  std::optional<StageBuffers> stage_images;
  std::optional<StageBufferTracer> stage_tracer;
  if (stage_vertex) {
    stage_images.emplace(compiled.scene().film.width, compiled.scene().film.height, *stage_vertex);
    stage_tracer.emplace(dynamic_cast<const WavefrontTracer&>(*tracer), *stage_images);
    inner = &*stage_tracer;
  }
  std::optional<BounceAccumulator> bounce_buffers;
  std::optional<BounceTracer> bounce_tracer;
  if (bounces_aov) {
    bounce_buffers.emplace(compiled.scene().film.width, compiled.scene().film.height);
    bounce_tracer.emplace(*inner, *bounce_buffers);
    inner = &*bounce_tracer;
  }
  std::optional<AovAccumulator> aov_buffers;
  std::optional<AovTracer> aov_tracer;
  if (!layers.empty()) {
    aov_buffers.emplace(compiled, settings);
    aov_tracer.emplace(*inner, *aov_buffers);
    inner = &*aov_tracer;
  }
  const Scene& sc = compiled.scene();
  if (const std::size_t n = compiled.lights().unsampled_light_count(); n > 0 && chatty)
    err << "pathlab: warning: " << n << " light(s) are too dim next to the others ever to be picked for light "
        << "sampling; only rays that hit them count their light\n";
  if (const std::optional<float> peak = constant_emitters_peak(sc); peak && *peak < kFilmFaintRadiance && chatty)
    err << "pathlab: warning: the brightest emitter's radiance is " << *peak
        << ": the film rounds each sample to a multiple of 2^-64 (an error of up to 2^-65, 2.7e-20), so below 2^-55 "
           "(2.8e-17) the image can lose about 0.1 % of its light or more to rounding, and below 2.7e-20 goes black "
           "(docs/overnight.md); choose a smaller unit of radiance (scale the emission up)\n";
  if (const std::optional<EmitterPeak> peak = brightest_constant_emitter(sc);
      peak && !(peak->radiance < kFilmRadianceLimit) && chatty)
    err << "pathlab: warning: " << peak->source << " emits radiance " << peak->radiance
        << ", beyond the film's range (below 2^32, 4.3e9): every sample that sees it is left out of the image and "
           "counted as bad (docs/overnight.md); choose a larger unit of radiance (scale the emission down)\n";
  if (const LightBvh* bvh = compiled.lights().bvh(); bvh && chatty && !quiet && !bvh->empty())
    err << "pathlab: light BVH: " << (bvh->node_count() + 1) / 2 << " lights, " << bvh->node_count()
        << " nodes, depth " << bvh->depth() << "\n";
  // The second moments only if something reads them: progressive rendering
  // estimates its error from them, and the variance AOV is them. A resumed
  // film keeps what it was made with.
  const bool variance = progressive || variance_aov;
  Film film = resumed && job.rank() == 0 ? std::move(resumed->film)
                      : Film(sc.film.width, sc.film.height, sc.film.filter,
                             variance ? FilmMoments::MeanAndVariance : FilmMoments::Mean);
  PartialFilmInfo info;
  if (resumed) {
    info = resumed->info;
    ++info.resumes;
  } else {
    info.passes = {range.begin, range.begin};
    info.fingerprint = fingerprint;
  }
  info.target_spp = progressive && !scene.spp ? 1u << 24 : range.end;
  const PartialFilmInfo before = info;
  if (resumed && !quiet && chatty)
    err << "pathlab: resuming " << *resume << ": passes " << info.passes.begin << ".." << info.passes.end
        << " done, " << info.resumes - 1 << " resume(s) before\n";
  const std::uint32_t start = info.passes.end;
  // The partial film `f` after this run's passes up to `end`, with its stats so far.
  const auto info_of = [&](const Film& f, std::uint32_t end, const RenderStats& so_far) {
    PartialFilmInfo i = before;
    i.passes.end = end;
    i.stats += so_far;
    i.stats.seconds = before.stats.seconds + so_far.seconds;
    i.stats.bad_samples = f.bad_sample_count();
    return i;
  };
  const auto info_at = [&](std::uint32_t end, const RenderStats& so_far) { return info_of(film, end, so_far); };

  const InterruptGuard interrupts;
  // True (and the clock restarted) when a checkpoint is due.
  auto last_checkpoint = std::chrono::steady_clock::now();
  const auto checkpoint_due = [&] {
    const auto now = std::chrono::steady_clock::now();
    if (!checkpoint || std::chrono::duration<double>(now - last_checkpoint).count() < checkpoint_every) return false;
    last_checkpoint = now;
    return true;
  };
  const BatchDoneFn batch_done = [&](std::uint32_t end, const RenderStats& so_far) {
    if (InterruptGuard::received() != 0) return false;
    if (checkpoint_due()) write_partial_film(film, info_at(end, so_far), *checkpoint);
    return true;
  };

  ProgressBar bar(err, "rendering", !quiet && chatty && stderr_is_terminal());
  const Tracer& driven = *inner;
  std::optional<UntilResult> until;
  RenderStats stats;
  std::uint32_t end = start;
  int interrupted = 0;
  if (job.distributed()) {
    // Every rank renders its blocks of passes into its own film; rank 0's
    // also holds what a checkpoint it resumed from held, so the sum is the
    // whole render. Rank 0 writes the checkpoints and the outputs.
    const std::uint32_t block = batch_size(film.width(), film.height(), static_cast<int>(range.end - start));
    const MpiJob::Result r = job.render(
        driven, film, start, range.end, block, [] { return InterruptGuard::received() != 0; }, checkpoint_due,
        [&](std::uint32_t reached, Film& sum, const RenderStats& total) {
          // Every reduction is a checkpoint, the last one too (at the end
          // or on an interrupt): the one write of it.
          stats = total;
          if (checkpoint) write_partial_film(sum, info_of(sum, reached, total), *checkpoint);
          film = std::move(sum);  // the last one is the job's film
        },
        [&](double f) { bar.update(f); });
    bar.finish();
    if (job.rank() != 0) return 0;
    end = r.end;
    if (!quiet)
      err << "pathlab: mpi: " << job.size() << " ranks, " << r.reductions << " reduction(s) of "
          << r.film_bytes / (static_cast<std::uint64_t>(film.width()) * film.height()) << " bytes per pixel ("
          << r.film_bytes / (1024 * 1024) << " MiB per rank), " << static_cast<int>(1000.0 * r.reduce_seconds)
          << " ms in them on rank 0\n";
    interrupted = r.stopped ? (InterruptGuard::received() != 0 ? InterruptGuard::received() : SIGTERM) : 0;
  } else if (progressive) {
    // Without an explicit --spp the budget or target decides alone.
    until = render_until(driven, film, {time_budget.value_or(0.0), target_relmse.value_or(0.0),
                                        scene.spp ? settings.spp : 1 << 24, 0},
                         [&](double f) { bar.update(f); }, start, batch_done);
    stats = until->stats;
    end = until->spp;
  } else {
    stats = render_samples(driven, film, start, range.end, [&](double f) { bar.update(f); }, batch_done);
    const auto pixels = static_cast<std::uint64_t>(film.width()) * film.height();
    end = start + static_cast<std::uint32_t>(stats.samples / std::max<std::uint64_t>(pixels, 1));
  }
  bar.finish();
  if (!job.distributed()) interrupted = InterruptGuard::received();
  info = info_at(end, stats);
  if (checkpoint && !job.distributed()) write_partial_film(film, info, *checkpoint);  // MPI: written as reduced
  if (partial_output) write_partial_film(film, info, exr);
  const int spp_done = static_cast<int>(info.passes.count());
  stats = info.stats;  // this render and the ones it resumed

  if (!partial_output) {
    const Image image = film.image();
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.3f", stats.seconds);
    char clamped_fraction[32];
    std::snprintf(clamped_fraction, sizeof clamped_fraction, "%.6g", stats.relative_energy_clamped());
    // Every setting that changes a sample (core/render.h), then what the
    // render did and what made it (docs/scene-format.md, "EXR metadata").
    ImageMetadata meta = {
        {"scene", sc.file.empty() ? "<built-in " + sc.name + ">" : sc.file.string()},
        {"tracer", std::string(tracer->name())},
        {"spp", std::to_string(spp_done)},
        {"resolution", std::to_string(sc.film.width) + "x" + std::to_string(sc.film.height)},
        {"filter", sc.film.filter == FilterKind::Box ? "box" : "bilinear"},
    };
    for (auto& kv : sample_settings(settings)) meta.push_back(std::move(kv));
    const std::vector<std::pair<std::string, std::string>> made = {
        {"clamped", settings.clamp > 0.0f ? "yes" : "no"},
        {"clamped_samples", std::to_string(stats.clamped_samples)},
        {"clamped_energy_fraction", clamped_fraction},
        {"render_time_seconds", seconds},
        {"simd", simd_target_name(active_simd_target())},
        {"bad_samples", std::to_string(stats.bad_samples)},
        {"version", PATHLAB_VERSION},
        {"git_revision", git_revision()},
        {"command_line", command_line},
    };
    for (const auto& kv : made) meta.push_back(kv);
    for (auto& kv : partial_film_metadata(info)) meta.push_back(std::move(kv));
    if (interrupted != 0) meta.emplace_back("interrupted", "yes");
    if (progressive) {
      char relmse[32];
      std::snprintf(relmse, sizeof relmse, "%.6g", until->estimated_relmse);
      meta.emplace_back("spp_reached", std::to_string(spp_done));
      meta.emplace_back("estimated_relmse", relmse);
      if (time_budget) meta.emplace_back("time_budget_seconds", std::to_string(*time_budget));
      if (target_relmse) meta.emplace_back("target_relmse", std::to_string(*target_relmse));
    }
    if (layers.empty()) write_exr(exr, image, meta);
    else
      write_exr_channels(exr, film.width(), film.height(),
                         aov_channels(film, *aov_buffers, layers, bounce_buffers ? &*bounce_buffers : nullptr), meta);
    write_png_beside(exr, png, image, exposure);
    if (stage_images) {
      meta.emplace_back("stage_buffers_vertex", std::to_string(*stage_vertex));
      const auto files = stage_images->write(stage_dir, meta);
      if (!quiet) err << "pathlab: wrote the wavefront's arrays at bounce " << *stage_vertex << " (scalar stages) to "
                      << stage_dir.string() << "/bounce" << *stage_vertex << "-*.exr (" << files.size() << " images)\n";
    }
  }
  if (interrupted != 0) {
    err << "pathlab: interrupted (" << (interrupted == SIGINT ? "SIGINT" : "SIGTERM") << ") after passes "
        << info.passes.begin << ".." << info.passes.end << "; wrote " << exr.string()
        << (checkpoint ? " and the checkpoint " + *checkpoint + " (go on with --resume " + *checkpoint + ")" : "")
        << "\n";
  }

  if (const std::uint64_t refused = embree_rejected_rays(); refused > 0)
    err << "pathlab: warning: " << refused
        << " ray(s) were NaN or beyond 1.8e18 and were not traced (Embree would abort on them); their samples "
           "count as bad samples\n";
  if (stats.bad_samples > 0) {
    err << "pathlab: warning: " << stats.bad_samples
        << " sample(s) had NaN, infinite or out-of-range (>= 2^32) radiance and were left out of the image. "
           "Replay them with:\n";
    for (const BadSample& b : film.bad_samples())
      err << "  " << scene.trace_pixel_command(sc, b.x, b.y, b.sample) << "\n";
  }
  if (!quiet) {
    char line[256];
    std::snprintf(line, sizeof line, "%.2f s, %.3g samples/s, %.3g rays/s", stats.seconds,
                  static_cast<double>(stats.samples) / std::max(stats.seconds, 1e-9),
                  static_cast<double>(stats.rays) / std::max(stats.seconds, 1e-9));
    err << "pathlab: wrote " << exr.string() << (partial_output ? "" : " and " + png.string()) << " (" << sc.film.width << "x"
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
      if (bounce_tracer || stage_tracer)
        err << "pathlab: wavefront: this render ran the scalar stages ("
            << (bounce_tracer ? "--aov bounces traces each sample with an observer, one path per wave"
                              : "--dump-stage-buffers records the scalar stages' arrays")
            << ")\n";
      if (const WavefrontTimes t = wf->times(); t.waves_seconds > 0.0) {
        std::snprintf(line, sizeof line,
                      "%.0f%% of the waves' time in Embree; per thread, camera %.3g, bounce %.3g, shadow %.3g rays/s",
                      100.0 * t.query_seconds() / t.waves_seconds, t.camera.rays_per_second(),
                      t.bounce.rays_per_second(), t.shadow.rays_per_second());
        err << "pathlab: wavefront: " << line << "\n";
        // The stages' own shares of the waves' time (Embree's batches apart).
        std::string stages = "pathlab: wavefront: stages (of the waves' time):";
        for (int k = 0; k < kWavefrontStages; ++k) {
          std::snprintf(line, sizeof line, "%s %s %.1f%%", k ? "," : "", wavefront_stage_name(static_cast<WavefrontStage>(k)),
                        100.0 * t.stage_seconds[k] / t.waves_seconds);
          stages += line;
        }
        err << stages << "\n";
      }
    }
  }
  // 128 + the signal, as a shell reports a process the signal ended.
  return interrupted != 0 ? 128 + interrupted : 0;
}

}  // namespace pathlab::cli
