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

// argv as one line a POSIX shell reads back to the same words: a word with
// anything but [A-Za-z0-9_@%+=:,./-] is put in single quotes.
std::string shell_command_line(int argc, const char* const* argv);

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
  std::string command_line;  // as typed (shell-quoted), for the EXR header
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
  double threshold = 1e-6;  // --threshold: a pixel differs when max |A - B| over its channels exceeds it
  bool stat = false;        // --stat: the statistical test decides the exit code
  double alpha = 1e-4;      // --alpha: its family-wise false-alarm rate
  bool log_scale = false;   // --log: the heatmap's scale
  std::optional<std::string> range;  // --range LO,HI: the heatmap's range
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
  std::string command_line;  // as typed (shell-quoted), for the header
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
  std::vector<std::string> samplers;    // --samplers A,B -> options.samplers
  std::optional<std::string> sampler;   // --sampler K: the scene's sampler
  std::vector<std::string> light_samplings;  // --light-samplings A,B -> options.light_samplings
  std::vector<std::string> light_samplers;   // --light-samplers A,B -> options.light_samplers
  std::optional<double> target_rmse;
  std::optional<std::string> resolution;  // "WxH"
  int threads = 0;
  std::string out_dir;
  bool selected = false;
  void add_to(CLI::App& app);
  int run(std::ostream& out, std::ostream& err) const;
};

}  // namespace pathlab::cli
