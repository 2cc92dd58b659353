// pathlab trace-pixel [SCENE] --pixel X,Y [--sample S | --samples A..B] [--seed S] [--json] [--vtk out.vtp] ...
// Replays pixel samples on one thread and prints every event of their paths;
// --vtk also writes them as VTK polylines (docs/path-vtk.md).
#include "apps/cli/commands.h"

#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/parallel.h"
#include "core/tracer.h"
#include "debugtools/path_compare.h"
#include "debugtools/path_recorder.h"
#include "debugtools/scene_geometry.h"
#include "debugtools/vtk_export.h"

#include <ostream>
#include <sstream>
#include <vector>

namespace pathlab::cli {

void TracePixelCommand::add_to(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("trace-pixel", "Replay one pixel sample and print its path");
  scene.add_to(*cmd, false, true);
  cmd->add_option("--spp", scene.spp,
                  "The samples per pixel of the render replayed: only the zsobol sampler's numbers depend on it")
      ->check(CLI::Range(1, 1 << 24));
  cmd->add_option("--pixel", pixel, "Pixel X,Y (0,0 = top left)")->required();
  CLI::Option* one = cmd->add_option("--sample", sample, "Sample index within the pixel");
  cmd->add_option("--samples", samples, "A range of samples A..B (inclusive), e.g. 0..15")->excludes(one);
  cmd->add_flag("--json", json, "Print the path as JSON on stdout (docs/trace-pixel-json.md); one sample only");
  CLI::Option* vtk_option = cmd->add_option("--vtk", vtk, "Also write the paths as VTK PolyData (.vtp, docs/path-vtk.md)");
  cmd->add_option("--vtk-geometry", vtk_geometry,
                  "With --vtk: also the triangles the paths hit (hit) or the whole scene (scene), as OUT.geometry.vtp "
                  "and OUT.vtm opening both")
      ->check(CLI::IsMember({"hit", "scene"}))
      ->needs(vtk_option);
  cmd->add_option("--vtk-max-triangles", vtk_max_triangles,
                  "--vtk-geometry scene: write the whole scene only up to this many triangles (spheres tessellated)")
      ->check(CLI::PositiveNumber);
  cmd->callback([this] { selected = true; });
}

int TracePixelCommand::run(std::ostream& out, std::ostream& err) const {
  Scene s = scene.load();
  for (const std::string& w : s.warnings) err << "pathlab: warning: " << w << "\n";
  long x = -1, y = -1;
  char comma = 0, extra = 0;
  std::istringstream in(pixel);
  if (!(in >> x >> comma >> y) || comma != ',' || (in >> extra))
    throw InputError("--pixel " + pixel + ": expected X,Y, e.g. --pixel 120,64");
  if (x < 0 || y < 0 || x >= s.film.width || y >= s.film.height)
    throw InputError("--pixel " + pixel + ": outside the " + std::to_string(s.film.width) + "x" +
                     std::to_string(s.film.height) + " image");

  std::uint32_t first = sample, last = sample;
  if (!samples.empty()) {
    long a = -1, b = -1;
    char dot1 = 0, dot2 = 0;
    std::istringstream range(samples);
    if (!(range >> a >> dot1 >> dot2 >> b) || dot1 != '.' || dot2 != '.' || (range >> extra) || a < 0 || b < a ||
        b > 0xffffffffL)
      throw InputError("--samples " + samples + ": expected A..B with 0 <= A <= B, e.g. --samples 0..15");
    first = static_cast<std::uint32_t>(a);
    last = static_cast<std::uint32_t>(b);
  }
  if (json && last > first) throw InputError("--json prints one sample: use --sample S (or --samples S..S)");
  if (scene.tracer == "both" && last > first) throw InputError("--tracer both replays one sample: use --sample S");
  if (!vtk.empty() && scene.tracer == "both") throw InputError("--vtk needs one tracer (reference or wavefront), not both");
  if (!vtk.empty()) {  // fail before tracing
    if (!vtk_export_available()) write_path_vtp(vtk, {});  // throws: built without VTK
    ensure_writable(vtk);
    if (!vtk_geometry.empty()) ensure_writable(multiblock_path(vtk));
  }

  const ThreadLimit one_thread(1);
  const RenderSettings settings = s.render;
  const CompiledScene compiled(std::move(s));
  const Scene& sc = compiled.scene();
  const auto ux = static_cast<std::uint32_t>(x), uy = static_cast<std::uint32_t>(y);
  auto record = [&](const std::string& name, std::uint32_t sample_index, PathRecorder& recorder) {
    make_tracer(name, compiled, settings)->trace_sample(ux, uy, sample_index, &recorder);
    return TraceHeader{sc.file.empty() ? "<built-in " + sc.name + ">" : sc.file.string(), name, ux, uy, sample_index,
                       settings, sc.film.width, sc.film.height, command_line};
  };
  if (scene.tracer != "both") {
    std::vector<PathLine> lines;
    std::vector<PathRecorder> recorders;  // for --vtk-geometry
    for (std::uint32_t s_index = first;; ++s_index) {
      PathRecorder& recorder = recorders.emplace_back();
      const TraceHeader header = record(scene.tracer, s_index, recorder);
      if (json) out << path_to_json(header, recorder, sc).dump(2) << "\n";
      else err << path_to_text(header, recorder, sc);
      // Escaping rays end a bounding-sphere diameter away.
      for (PathLine& l : path_lines(recorder, s_index, 2.0f * compiled.bounds_radius())) lines.push_back(std::move(l));
      if (s_index == last) break;
    }
    if (!vtk.empty() && !vtk_geometry.empty()) {
      const SceneGeometry g = scene_geometry(sc, recorders, vtk_geometry == "scene" ? GeometryScope::Scene : GeometryScope::Hit,
                                             vtk_max_triangles);
      write_paths_and_geometry(vtk, lines, g);
      err << "pathlab: wrote " << vtk << " (" << (last - first + 1) << " path(s), " << lines.size() << " lines), "
          << geometry_vtp_path(vtk).string() << " (" << g.triangles.size() << " of the scene's " << g.scene_triangles
          << " triangles" << (g.complete ? "" : vtk_geometry == "scene" && g.scene_triangles > vtk_max_triangles
                                                   ? ": over --vtk-max-triangles " + std::to_string(vtk_max_triangles) +
                                                         ", so only those the paths hit"
                                                   : ": those the paths hit")
          << ") and " << multiblock_path(vtk).string() << " (opens both)\n";
    } else if (!vtk.empty()) {
      write_path_vtp(vtk, lines);
      err << "pathlab: wrote " << vtk << " (" << (last - first + 1) << " path(s), " << lines.size() << " lines)\n";
    }
    return 0;
  }

  // Both tracers, event by event, marking where the paths part.
  PathRecorder ref, wave;
  const TraceHeader href = record("reference", sample, ref), hwave = record("wavefront", sample, wave);
  const PathDivergence d = first_divergence(ref.events(), wave.events(), 1e-4f);
  if (json) {
    nlohmann::json j = {{"format", "pathlab-trace-pair"}, {"version", 1},
                        {"reference", path_to_json(href, ref, sc)}, {"wavefront", path_to_json(hwave, wave, sc)}};
    j["divergence"] = d.identical ? nlohmann::json(nullptr)
                                  : nlohmann::json{{"event", d.event}, {"vertex", d.vertex}, {"reason", d.reason},
                                                   {"rounding", d.rounding}};
    out << j.dump(2) << "\n";
    return 0;
  }
  err << trace_header_text(TraceHeader{href.scene, "reference | wavefront", ux, uy, sample, settings, sc.film.width,
                                       sc.film.height, command_line});
  const std::size_t n = std::max(ref.events().size(), wave.events().size());
  for (std::size_t i = 0; i < n; ++i) {
    if (!d.identical && i == d.event)
      err << ">>> the paths part here: " << d.reason << (d.rounding ? " (a floating-point difference)" : "") << "\n";
    auto line = [&](const char* who, const PathRecorder& r) {
      std::string text = i < r.events().size() ? event_to_text(r.events()[i], sc) : std::string("(no event)\n");
      std::string indented;
      for (std::size_t p = 0, q; p < text.size(); p = q + 1) {
        q = text.find('\n', p);
        indented += std::string(who) + text.substr(p, q - p + 1);
      }
      err << indented;
    };
    line("ref  ", ref);
    line("wave ", wave);
  }
  err << result_text(href, ref, "ref   ") << result_text(hwave, wave, "wave  ")
      << (d.identical ? "the paths agree at every event (tolerance 1e-4)\n" : "");
  return 0;
}

}  // namespace pathlab::cli
