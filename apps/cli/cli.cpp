#include "apps/cli/cli.h"

#include "apps/cli/commands.h"
#include "core/error.h"

#include <iostream>

namespace pathlab::cli {

int run(int argc, const char* const* argv) { return run(argc, argv, std::cout, std::cerr); }

int run(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app("pathlab: get path tracing right, then fast", "pathlab");
  app.set_version_flag("--version", PATHLAB_VERSION);
  app.require_subcommand(1);
  RenderCommand render;
  TracePixelCommand trace_pixel;
  DiffCommand diff;
  CheckCommand check;
  ConvergeCommand converge;
  CompareCommand compare;
  MergeCommand merge;
  render.add_to(app);
  merge.add_to(app);
  check.add_to(app);
  diff.add_to(app);
  trace_pixel.add_to(app);
  converge.add_to(app);
  compare.add_to(app);
  render.command_line = trace_pixel.command_line = shell_command_line(argc, argv);

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e, out, err);
  } catch (const CLI::ParseError& e) {
    err << "pathlab: error: " << e.what() << "\n";
    err << "Run 'pathlab " << (app.get_subcommands().empty() ? "" : app.get_subcommands().front()->get_name() + " ")
        << "--help' for the options.\n";
    return 2;
  }

  try {
    if (render.selected) return render.run(out, err);
    if (merge.selected) return merge.run(out, err);
    if (trace_pixel.selected) return trace_pixel.run(out, err);
    if (diff.selected) return diff.run(out, err);
    if (check.selected) return check.run(out, err);
    if (converge.selected) return converge.run(out, err);
    if (compare.selected) return compare.run(out, err);
  } catch (const InputError& e) {
    err << "pathlab: error: " << e.what() << "\n";
    return 2;
  } catch (const SystemError& e) {
    err << "pathlab: error: " << e.what() << "\n";
    return 3;
  } catch (const std::bad_alloc&) {
    err << "pathlab: error: out of memory\n";
    return 3;
  } catch (const std::exception& e) {
    // Nothing should get here; if it does, say what it was rather than abort.
    err << "pathlab: error: internal error: " << e.what() << "\n";
    return 3;
  }
  return 2;
}

}  // namespace pathlab::cli
