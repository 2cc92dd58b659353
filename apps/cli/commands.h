// The subcommands of `pathlab`, each an options struct that registers itself
// on the CLI11 app and runs. run() may throw InputError (exit 2).
#pragma once

#include "apps/cli/scene_options.h"
#include "debugtools/converge.h"

#include <CLI/CLI.hpp>

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace pathlab::cli {

struct RenderCommand {
  SceneOptions scene;
  std::string output;
  std::vector<std::string> aovs;  // --aov albedo,normal,...: extra EXR layers
  int threads = 0;
  float exposure = 0.0f;
  std::optional<double> time_budget;    // --time SECONDS: stop at a whole pass before the budget
  std::optional<double> target_relmse;  // --target-relmse X: stop when the estimated relMSE < X
  std::optional<std::string> checkpoint;  // --checkpoint FILE: the partial film, kept up to date
  double checkpoint_every = 600.0;        // --checkpoint-every SECONDS
  std::optional<std::string> resume;      // --resume FILE
  std::optional<std::string> passes;      // --passes A..B
  std::vector<std::string> stage_buffers;  // --dump-stage-buffers K DIR
  bool quiet = false;
  bool selected = false;
  void add_to(CLI::App& app);
  int run(std::ostream& out, std::ostream& err) const;
};

// pathlab merge PART.pfilm... -o out.exr [--film merged.pfilm]
struct MergeCommand {
  std::vector<std::string> parts;
  std::string output;
  std::string film;  // also write the merged partial film here
  float exposure = 0.0f;
  bool quiet = false;
  bool selected = false;
  void add_to(CLI::App& app);
  int run(std::ostream& out, std::ostream& err) const;
};

// pathlab check SCENE [--tracer T] [--strategy S] [--spp N] [--seed S] [--out DIR]
struct CheckCommand {
  SceneOptions scene;
  std::string out_dir;
  int threads = 0;
  double alpha = 1e-4;
  bool selected = false;
  void add_to(CLI::App& app);
  int run(std::ostream& out, std::ostream& err) const;
};

// pathlab diff A.exr B.exr [--heatmap out.png] [--json] [--tolerance X --metric M]
struct DiffCommand {
  std::string a, b;
  std::string heatmap;
  bool json = false;
  std::optional<double> tolerance;
  std::string metric = "rmse";
  bool selected = false;
  void add_to(CLI::App& app);
  int run(std::ostream& out, std::ostream& err) const;
};

struct TracePixelCommand {
  SceneOptions scene;
  std::string pixel;  // "X,Y"
  std::uint32_t sample = 0;
  std::string samples;  // "A..B", inclusive; excludes --sample
  std::string vtk;      // --vtk out.vtp
  std::string vtk_geometry;                   // --vtk-geometry hit|scene
  std::size_t vtk_max_triangles = 1000000;    // --vtk-max-triangles N
  bool json = false;
  bool selected = false;
  void add_to(CLI::App& app);
  int run(std::ostream& out, std::ostream& err) const;
};

// pathlab compare [SCENE] [--tracers A,B] [--with OTHER] [--export FILE] [--json]:
// two tracers or two builds at the same seed (debugtools/compare.h, docs/compare.md).
struct CompareCommand {
  SceneOptions scene;
  CLI::Option* tracer_option = nullptr;  // SceneOptions' --tracer, refused here
  std::vector<std::string> tracers;      // --tracers A,B
  std::string with;                      // --with: the other build's binary
  std::string export_file;               // --export FILE
  double alpha = 1e-4;
  int threads = 0;
  bool json = false;
  bool selected = false;
  void add_to(CLI::App& app);
  int run(std::ostream& out, std::ostream& err) const;
};

// pathlab converge SCENE ... --out DIR: the speed-accuracy sweep
// (debugtools/converge.h, docs/converge.md).
struct ConvergeCommand {
  std::string scene_file;
  ConvergeOptions options;              // the options bind to its fields, but for these two:
  std::string reference;                // -> options.reference
  std::vector<std::string> strategies;  // -> options.strategies
  std::optional<double> target_rmse;
  std::optional<std::string> resolution;  // "WxH"
  int threads = 0;
  std::string out_dir;
  bool selected = false;
  void add_to(CLI::App& app);
  int run(std::ostream& out, std::ostream& err) const;
};

}  // namespace pathlab::cli
