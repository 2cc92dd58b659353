// pathlab trace-pixel [SCENE] --pixel X,Y [--sample S] [--seed S] [--json] ...
// Replays one pixel sample on one thread and prints every event of its path.
#include "apps/cli/commands.h"

#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/tracer.h"
#include "debugtools/path_recorder.h"

#include <ostream>
#include <sstream>

namespace pathlab::cli {

void TracePixelCommand::add_to(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("trace-pixel", "Replay one pixel sample and print its path");
  scene.add_to(*cmd, false);
  cmd->add_option("--pixel", pixel, "Pixel X,Y (0,0 = top left)")->required();
  cmd->add_option("--sample", sample, "Sample index within the pixel");
  cmd->add_flag("--json", json, "Print the path as JSON on stdout (docs/trace-pixel-json.md)");
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

  const ThreadLimit one_thread(1);
  const RenderSettings settings = s.render;
  const CompiledScene compiled(std::move(s));
  const auto tracer = make_tracer(scene.tracer, compiled, settings);
  PathRecorder recorder;
  tracer->trace_sample(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), sample, &recorder);

  const Scene& sc = compiled.scene();
  TraceHeader header{sc.file.empty() ? "<built-in " + sc.name + ">" : sc.file.string(), std::string(tracer->name()),
                     static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), sample, settings,
                     sc.film.width, sc.film.height};
  if (json) out << path_to_json(header, recorder, sc).dump(2) << "\n";
  else err << path_to_text(header, recorder, sc);
  return 0;
}

}  // namespace pathlab::cli
