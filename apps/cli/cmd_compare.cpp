// pathlab compare [SCENE] [--tracers A,B] [--spp N] [--seed S] [--json] [--with OTHER-PATHLAB] [--export FILE]
// Renders a scene with two tracers, or with this build and another one, at
// the same seed, and says whether they agree sample by sample (the
// same-seed rule of debugtools/compare.h) and bounce by bounce; where they
// do not, the first disagreeing sample, its first divergent event and the
// command that replays it. Exit 0: they agree; 1: they do not; 2: bad input.
// docs/compare.md.
#include "apps/cli/commands.h"

#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/tracer.h"
#include "debugtools/compare.h"
#include "debugtools/path_recorder.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>

extern char** environ;

namespace pathlab::cli {

void CompareCommand::add_to(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "compare", "Render with two tracers (or two builds) at the same seed and say where they part");
  scene.add_to(*cmd, true);
  tracer_option = cmd->get_option("--tracer");
  cmd->add_option("--tracers", tracers,
                  "The two sides, A,B: reference or wavefront (default reference,wavefront; with --with "
                  "wavefront,wavefront: A here, B in the other build)")
      ->delimiter(',')
      ->expected(1, 2)
      ->check(CLI::IsMember({"reference", "wavefront"}));
  cmd->add_option("--with", with,
                  "Another build's pathlab binary: B is rendered by it (compare --export) and its disagreeing sample "
                  "replayed by its trace-pixel --json");
  cmd->add_option("--export", export_file,
                  "Render only A and write its samples and per-bounce sums to FILE (what --with reads)");
  cmd->add_option("--alpha", alpha, "False-alarm rate of the per-bounce tests (Šidák-corrected; default 1e-4)")
      ->check(CLI::Range(1e-12, 0.5));
  cmd->add_option("--threads", threads, "Worker threads (0 = all)")->check(CLI::Range(0, 4096));
  cmd->add_flag("--json", json, "Print the report as JSON on stdout (docs/compare.md)");
  cmd->callback([this] { selected = true; });
}

namespace {

// The scene options as arguments, for the other build (trace-pixel takes
// --spp only for the zsobol sampler, whose numbers depend on it).
std::vector<std::string> scene_args(const SceneOptions& o, bool with_spp) {
  std::vector<std::string> a;
  if (!o.scene_file.empty()) a.push_back(o.scene_file);
  const auto opt = [&](const char* name, const auto& value) {
    if (value) {
      std::ostringstream v;
      v << *value;
      a.push_back(name);
      a.push_back(v.str());
    }
  };
  opt("--strategy", o.strategy);
  if (with_spp || o.sampler) opt("--spp", o.spp);
  opt("--sampler", o.sampler);
  opt("--max-depth", o.max_depth);
  opt("--rr-depth", o.rr_depth);
  opt("--seed", o.seed);
  opt("--resolution", o.resolution);
  opt("--bsdf-sampling", o.bsdf_sampling);
  opt("--light-sampling", o.light_sampling);
  opt("--light-sampler", o.light_sampler);
  opt("--bvh", o.bvh);
  opt("--intersection", o.intersection);
  opt("--clamp", o.clamp);
  opt("--min-pdf", o.min_pdf);
  opt("--texture-filter", o.texture_filter);
  opt("--texture-cache-mb", o.texture_cache_mb);
  if (o.general_shading) a.emplace_back("--general-shading");
  return a;
}

std::string shell_quote(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./,:=+") ==
                        std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string command_line(const std::vector<std::string>& argv) {
  std::string s;
  for (const std::string& a : argv) s += (s.empty() ? "" : " ") + shell_quote(a);
  return s;
}

// Runs argv (argv[0] a path), its stdout into `out_file`, stderr ours.
// Throws InputError if it cannot start or fails.
void run_other(const std::vector<std::string>& argv, const std::string& out_file) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0].c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw InputError("--with " + argv[0] + ": cannot run it: " + std::strerror(rc));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw SystemError("--with " + argv[0] + ": waiting for it: " + std::strerror(errno));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw InputError("--with: `" + command_line(argv) + "` failed (" +
                     (WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status))
                                        : "signal " + std::to_string(WTERMSIG(status))) +
                     "); is it a pathlab build with `compare`?");
}

// A scratch folder, removed on the way out.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "pathlab-compare-XXXXXX").string();
    if (!mkdtemp(tmpl.data())) throw SystemError("cannot create a temporary folder: " + std::string(std::strerror(errno)));
    path = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

nlohmann::json j3(const Spectrum& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

std::string fmt3(const Spectrum& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", static_cast<double>(v.x), static_cast<double>(v.y),
                static_cast<double>(v.z));
  return buf;
}

}  // namespace

int CompareCommand::run(std::ostream& out, std::ostream& err) const {
  if (tracer_option && tracer_option->count() > 0)
    throw InputError("compare takes --tracers A,B (two tracers), not --tracer");
  if (!export_file.empty() && !with.empty()) throw InputError("--export writes one side; it cannot go with --with");
  std::vector<std::string> sides = tracers;
  if (sides.empty()) sides = with.empty() ? std::vector<std::string>{"reference", "wavefront"}
                                          : std::vector<std::string>{"wavefront", "wavefront"};
  if (sides.size() == 1 && export_file.empty())
    throw InputError("--tracers " + sides[0] + ": give two, A,B (or --export FILE to render one)");
  if (sides.size() == 2 && !export_file.empty())
    throw InputError("--export renders one tracer: give --tracers A");
  if (!with.empty() && !std::filesystem::is_regular_file(with))
    throw InputError("--with " + with + ": no such file (give the other build's pathlab binary)");

  Scene s = scene.load();
  if (!json)
    for (const std::string& w : s.warnings) err << "pathlab: warning: " << w << "\n";
  const ThreadLimit limit(threads);
  const RenderSettings settings = s.render;
  const auto spp = static_cast<std::uint32_t>(std::max(settings.spp, 1));
  const CompiledScene compiled(std::move(s));
  const Scene& sc = compiled.scene();
  const auto ta = make_tracer(sides[0], compiled, settings);

  if (!export_file.empty()) {
    SampleExport e;
    e.tracer = sides[0];
    e.width = sc.film.width;
    e.height = sc.film.height;
    e.spp = spp;
    e.seed = settings.seed;
    e.samples.resize(static_cast<std::size_t>(e.width) * static_cast<std::size_t>(e.height) * spp);
    ta->render_batch(0, spp, e.samples);
    e.bounces = render_bounces(*ta, spp);
    write_sample_export(export_file, e);
    return 0;
  }

  // The two sides: samples and per-bounce layers. Here, both are rendered
  // in batches; from another build, its whole export file is read.
  const BounceAccumulator ba = render_bounces(*ta, spp);
  std::vector<FilmSample> sa;
  std::unique_ptr<Tracer> tb;
  SampleExport other;
  std::optional<TempDir> tmp;
  if (with.empty()) {
    tb = make_tracer(sides[1], compiled, settings);
    other.bounces = render_bounces(*tb, spp);
  } else {
    sa.resize(static_cast<std::size_t>(sc.film.width) * static_cast<std::size_t>(sc.film.height) * spp);
    ta->render_batch(0, spp, sa);
    tmp.emplace();
    const std::string file = (tmp->path / "other.samples").string();
    std::vector<std::string> argv{with, "compare"};
    for (std::string& a : scene_args(scene, true)) argv.push_back(std::move(a));
    for (const char* a : {"--tracers", sides[1].c_str(), "--export", file.c_str()}) argv.emplace_back(a);
    if (threads > 0) argv.insert(argv.end(), {"--threads", std::to_string(threads)});
    run_other(argv, (tmp->path / "other.stdout").string());
    other = read_sample_export(file);
    if (other.width != sc.film.width || other.height != sc.film.height || other.spp != spp ||
        other.seed != settings.seed)
      throw InputError("--with " + with + ": it rendered a " + std::to_string(other.width) + "x" +
                       std::to_string(other.height) + " film at " + std::to_string(other.spp) + " spp, seed " +
                       std::to_string(other.seed) + ", not this build's " + std::to_string(sc.film.width) + "x" +
                       std::to_string(sc.film.height) + ", " + std::to_string(spp) + " spp, seed " +
                       std::to_string(settings.seed));
  }

  // Where a sample's paths part: both replayed here, or ours against the
  // other build's trace-pixel --json (both read back from JSON, so the two
  // carry the same fields).
  const auto header = [&](const std::string& tracer, std::uint32_t x, std::uint32_t y, std::uint32_t sample) {
    return TraceHeader{sc.file.empty() ? "<built-in " + sc.name + ">" : sc.file.string(), tracer, x, y, sample,
                       settings, sc.film.width, sc.film.height};
  };
  const ReplayFn replay = [&](std::uint32_t x, std::uint32_t y, std::uint32_t sample) -> PathDivergence {
    if (tb) return replay_divergence(*ta, *tb, x, y, sample);
    PathRecorder ours;
    ta->trace_sample(x, y, sample, &ours);
    std::vector<PathEvent> a =
        path_events_from_json(path_to_json(header(sides[0], x, y, sample), ours, sc), sc, "this build's trace");
    std::vector<std::string> argv{with, "trace-pixel"};
    for (std::string& arg : scene_args(scene, false)) argv.push_back(std::move(arg));
    for (const std::string& arg : {std::string("--pixel"), std::to_string(x) + "," + std::to_string(y),
                                   std::string("--sample"), std::to_string(sample), std::string("--tracer"), sides[1],
                                   std::string("--json")})
      argv.push_back(arg);
    const std::string json_file = (tmp->path / "trace.json").string();
    run_other(argv, json_file);
    std::ifstream in(json_file);
    nlohmann::json doc;
    try {
      in >> doc;
    } catch (const nlohmann::json::exception& e) {
      throw InputError("--with " + with + ": its trace-pixel --json is not JSON: " + e.what());
    }
    const std::vector<PathEvent> b = path_events_from_json(doc, sc, with + " trace-pixel --json");
    if (!trace_records_rays(doc)) forget_rays(a);  // an older build: compared on everything else
    return first_divergence(a, b, kReplayTolerance);
  };
  const SampleComparison samples =
      tb ? compare_tracers(*ta, *tb, spp) : compare_samples(sa, other.samples, sc.film.width, spp, 0, replay);
  const BounceComparison bounces = compare_bounces(ba, other.bounces, alpha);
  const bool agree = samples.agree() && bounces.agree();

  // The commands that replay the first disagreeing sample.
  std::vector<std::string> replay_commands;
  const SampleDisagreement* first = samples.replayed.empty() ? nullptr : &samples.replayed.front();
  if (first) {
    SceneOptions o = scene;
    if (with.empty()) {
      o.tracer = "both";
      replay_commands.push_back(o.trace_pixel_command(sc, first->x, first->y, first->sample));
    } else {
      o.tracer = sides[0];
      replay_commands.push_back(o.trace_pixel_command(sc, first->x, first->y, first->sample));
      o.tracer = sides[1];
      std::string theirs = o.trace_pixel_command(sc, first->x, first->y, first->sample);
      replay_commands.push_back(shell_quote(with) + theirs.substr(std::string("pathlab").size()));
    }
  }
  const std::string name_b = with.empty() ? sides[1] : sides[1] + " (" + with + ")";

  if (json) {
    nlohmann::json j = {{"format", "pathlab-compare"},
                        {"version", 1},
                        {"scene", sc.file.empty() ? "<built-in " + sc.name + ">" : sc.file.string()},
                        {"a", sides[0]},
                        {"b", sides[1]},
                        {"with", with.empty() ? nlohmann::json(nullptr) : nlohmann::json(with)},
                        {"resolution", {sc.film.width, sc.film.height}},
                        {"spp", spp},
                        {"seed", settings.seed},
                        {"strategy", strategy_name(settings.strategy)},
                        {"agree", agree}};
    j["samples"] = {{"total", samples.samples},       {"equal", samples.equal},
                    {"differing", samples.differing()}, {"replayed", samples.replayed.size()},
                    {"unexplained", samples.unexplained}, {"agree", samples.agree()}};
    if (first) {
      const PathDivergence& d = first->divergence;
      j["first_disagreement"] = {
          {"pixel", {first->x, first->y}},
          {"sample", first->sample},
          {"a", {{"radiance", j3(first->a.L)}, {"rays", first->a.rays}, {"hits", first->a.hits}}},
          {"b", {{"radiance", j3(first->b.L)}, {"rays", first->b.rays}, {"hits", first->b.hits}}},
          {"divergence", d.identical ? nlohmann::json(nullptr)
                                     : nlohmann::json{{"event", d.event}, {"vertex", d.vertex}, {"reason", d.reason},
                                                      {"rounding", d.rounding}}},
          {"replay", replay_commands}};
    } else {
      j["first_disagreement"] = nullptr;
    }
    nlohmann::json layers = nlohmann::json::array();
    for (int depth = 0; depth < kBounceLayers; ++depth)
      for (Technique t : {Technique::Bsdf, Technique::Nee}) {
        const BounceComparison::Layer& L = bounces.layers[static_cast<std::size_t>(depth)][static_cast<std::size_t>(t)];
        layers.push_back({{"layer", bounce_layer_name(depth)},
                          {"technique", technique_name(t)},
                          {"disagree", L.disagree},
                          {"failing_pixels", L.failing_pixels},
                          {"worst_pixel",
                           {{"pixel", {L.worst_pixel.x, L.worst_pixel.y}},
                            {"channel", L.worst_pixel.channel},
                            {"z", L.worst_pixel.z},
                            {"a", L.worst_pixel.a},
                            {"b", L.worst_pixel.b}}},
                          {"image", {{"channel", L.image.channel}, {"z", L.image.z}, {"a", L.image.a}, {"b", L.image.b}}}});
      }
    j["bounces"] = {{"alpha", bounces.alpha},
                    {"pixel_threshold", bounces.pixel_threshold},
                    {"image_threshold", bounces.image_threshold},
                    {"first_depth", bounces.first_depth < 0 ? nlohmann::json(nullptr)
                                                            : nlohmann::json(bounce_layer_name(bounces.first_depth))},
                    {"layers", layers}};
    out << j.dump(2) << "\n";
    return agree ? 0 : 1;
  }

  char pct[32];
  std::snprintf(pct, sizeof pct, "%.3f", 100.0 * static_cast<double>(samples.equal) /
                                             static_cast<double>(std::max<std::size_t>(samples.samples, 1)));
  out << "pathlab compare: " << (sc.file.empty() ? "<built-in " + sc.name + ">" : sc.file.string()) << ", "
      << sc.film.width << "x" << sc.film.height << ", " << spp << " spp, seed " << settings.seed << ", "
      << strategy_name(settings.strategy) << ": A = " << sides[0] << ", B = " << name_b << "\n";
  out << "samples: " << samples.equal << " of " << samples.samples << " agree (" << pct << " %, 99.9 % needed); "
      << samples.differing() << " differ, " << samples.replayed.size() << " replayed, " << samples.unexplained
      << " not explained by rounding\n";
  if (first) {
    const PathDivergence& d = first->divergence;
    out << "first disagreeing sample (row-major pixel, then sample): pixel " << first->x << "," << first->y
        << " sample " << first->sample << ": A " << fmt3(first->a.L) << " (" << first->a.hits << " hits, "
        << first->a.rays << " rays), B " << fmt3(first->b.L) << " (" << first->b.hits << " hits, " << first->b.rays
        << " rays)\n";
    if (d.identical)
      out << "  replayed, the two paths agree at every event (tolerance " << kReplayTolerance << ")\n";
    else
      out << "  first divergence: " << d.reason
          << (d.rounding ? " (a floating-point difference flipped a decision)" : " (not a rounding difference)") << "\n";
    for (const std::string& c : replay_commands) out << "  replay: " << c << "\n";
  }
  out << "per-bounce layers: z-test per pixel, channel, depth and technique (|z| > "
      << bounces.pixel_threshold << ") and per layer over the image (|z| > " << bounces.image_threshold
      << "), Šidák, alpha " << bounces.alpha << "\n";
  for (int depth = 0; depth < kBounceLayers; ++depth)
    for (Technique t : {Technique::Bsdf, Technique::Nee}) {
      const BounceComparison::Layer& L = bounces.layers[static_cast<std::size_t>(depth)][static_cast<std::size_t>(t)];
      if (!L.disagree) continue;
      out << "  " << bounce_layer_name(depth) << "." << technique_name(t) << " disagrees: " << L.failing_pixels
          << " pixel-channels beyond the threshold, worst pixel " << L.worst_pixel.x << "," << L.worst_pixel.y
          << " channel " << L.worst_pixel.channel << " z = " << L.worst_pixel.z << " (A " << L.worst_pixel.a << ", B "
          << L.worst_pixel.b << "); image mean z = " << L.image.z << " (A " << L.image.a << ", B " << L.image.b
          << ")\n";
    }
  if (bounces.agree()) out << "  every layer agrees\n";
  else out << "first depth that disagrees: " << bounce_layer_name(bounces.first_depth) << "\n";
  out << (agree ? "AGREE" : "DISAGREE") << "\n";
  return agree ? 0 : 1;
}

}  // namespace pathlab::cli
