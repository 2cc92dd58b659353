#include "apps/cli/cli.h"

#include "apps/cli/commands.h"
#include "apps/cli/interrupt.h"
#include "apps/cli/validators.h"
#include "core/error.h"
#include "core/json_document.h"
#include "core/messages.h"

#include <algorithm>
#include <iostream>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab::cli {
namespace {

// The finite-number check on every floating-point option (validators.h).
void require_finite_numbers(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    for (CLI::Option* option : sub->get_options())
      if (option->get_type_name().starts_with("FLOAT")) option->check(finite_number());  // "FLOAT:[0, 1]" too
}

}  // namespace

int run(int argc, const char* const* argv) {
  remove_temp_files_on_signals();
  return run(argc, argv, std::cout, std::cerr);
}

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
  require_finite_numbers(app);

  // A first word that is no command: CLI11 would say only "A subcommand is
  // required". Name it, and the command it is closest to.
  if (argc > 1 && argv[1][0] != '-') {
    const std::string word = argv[1];
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) names.push_back(sub->get_name());
    if (std::find(names.begin(), names.end(), word) == names.end()) {
      const std::vector<std::string_view> candidates(names.begin(), names.end());
      const std::string near = nearest_name(word, candidates);
      std::string list;
      for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
      err << "pathlab: error: unknown command " << quote_input(word)
          << (near.empty() ? " (the commands: " + list + ")" : " (did you mean '" + near + "'?)") << "\n";
      err << "Run 'pathlab --help' for the commands.\n";
      return 2;
    }
  }

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
