// pathlab-debug [SCENE] [--script FILE] [--screenshot PNG] [render overrides]
// Parses the command line and runs the viewer (debugtools/gui/app.h).
#include "debugtools/gui/app.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>

int main(int argc, char** argv) {
  using namespace pathlab;
  debug::AppOptions o;
  std::optional<std::string> strategy, resolution;
  int threads = 0;
  std::string materials = "authored";
  CLI::App app("pathlab-debug: watch a render converge, inspect pixels, replay and export paths");
  app.add_option("scene", o.session.scene_file, "Scene file (JSON); omit for the built-in Cornell box");
  app.add_option("--tracer", o.session.tracer, "reference or wavefront")->check(CLI::IsMember({"reference", "wavefront"}));
  app.add_option("--strategy", strategy, "cosine, bsdf, light, light+bsdf or mis");
  app.add_option("--spp", o.session.spp, "Samples per pixel to render")->check(CLI::Range(1, 1 << 24));
  app.add_option("--max-depth", o.session.max_depth, "Maximum bounces; -1 = until Russian roulette")
      ->check(CLI::Range(-1, kMaxVerticesUncapped));
  app.add_option("--seed", o.session.seed, "Random seed");
  app.add_option("--resolution", resolution, "Image size WxH");
  app.add_option("--threads", threads, "1 or 0 (all)")->check(CLI::IsMember({0, 1}));
  app.add_option("--materials", materials, "authored, white (Lambert) or mirror")
      ->check(CLI::IsMember({"authored", "white", "mirror"}));
  app.add_option("--view", o.view, "Any layer of the render (beauty, albedo, normal, depth, material, variance, pathlength, nonfinite, samples, ...) or nan");
  app.add_option("--exposure", o.exposure, "Exposure in stops");
  app.add_option("--script", o.script, "Run the commands of FILE (see debugtools/gui/script.h), then quit");
  app.add_option("--screenshot", o.screenshot, "Save the window as PNG when it closes");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (strategy) {
    o.session.strategy = parse_strategy(*strategy);
    if (!o.session.strategy) return std::cerr << "pathlab-debug: unknown strategy '" << *strategy << "'\n", 2;
  }
  if (resolution) {
    int w = 0, h = 0;
    char tail = 0;
    if (std::sscanf(resolution->c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 1 || h < 1 || w > 16384 || h > 16384)
      return std::cerr << "pathlab-debug: --resolution " << *resolution << ": expected WIDTHxHEIGHT, e.g. 640x480\n", 2;
    o.session.width = w;
    o.session.height = h;
  }
  o.session.all_threads = threads == 0;
  o.session.materials = *parse_material_override(materials);
  return debug::run_app(o, std::cerr);
}
