#include "debugtools/gui/script.h"

#include "core/error.h"
#include "debugtools/gui/views.h"
#include "debugtools/material_override.h"

#include <fstream>
#include <sstream>

namespace pathlab::debug {

std::vector<ScriptCommand> parse_script(const std::string& text, const std::string& file) {
  using Kind = ScriptCommand::Kind;
  std::vector<ScriptCommand> commands;
  std::istringstream lines(text);
  int number = 0;
  for (std::string line; std::getline(lines, line);) {
    ++number;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream in(line);
    std::string word;
    if (!(in >> word)) continue;
    ScriptCommand c;
    c.where = file + ":" + std::to_string(number);
    const auto fail = [&](const std::string& why) { throw InputError(c.where + ": " + why); };
    const auto ints = [&](int count) {
      if (!(in >> c.x) || (count == 2 && !(in >> c.y)) || c.x < 0 || c.y < 0)
        fail(word + " expects " + (count == 2 ? "two non-negative integers" : "a non-negative integer"));
    };
    const auto signed_int = [&](int& v) {
      if (!(in >> v)) fail(word + " expects an integer");
    };
    const auto name = [&] {
      if (!(in >> c.arg)) fail(word + " expects an argument");
    };
    if (word == "wait-spp") c.kind = Kind::WaitSpp, ints(1);
    else if (word == "hover") c.kind = Kind::Hover, ints(2);
    else if (word == "click") c.kind = Kind::Click, ints(2);
    else if (word == "sample") c.kind = Kind::Sample, ints(1);
    else if (word == "exposure") {
      c.kind = Kind::Exposure;
      if (!(in >> c.value)) fail("exposure expects a number of stops");
    } else if (word == "view") {
      c.kind = Kind::View, name();  // the layers exist only once the render runs: checked then
    } else if (word == "scale") {
      c.kind = Kind::Scale, name();
      if (!parse_mapping(c.arg)) fail("unknown scale '" + c.arg + "' (tone, normal, id, linear, log)");
    } else if (word == "mouse") c.kind = Kind::Mouse, ints(2);
    else if (word == "wheel") {
      c.kind = Kind::Wheel, ints(2);
      signed_int(c.dx);
    } else if (word == "drag") {
      c.kind = Kind::Drag, ints(2);
      signed_int(c.dx);
      signed_int(c.dy);
    } else if (word == "fit") c.kind = Kind::Fit;
    else if (word == "actual-size") c.kind = Kind::ActualSize;
    else if (word == "readout") c.kind = Kind::Readout, name();
    else if (word == "next-nan") c.kind = Kind::NextNan;
    else if (word == "compare") {
      c.kind = Kind::Compare, name();
      if (c.arg != "tracer" && c.arg != "off") fail("compare expects tracer or off (compare-image PATH for a file)");
    } else if (word == "compare-image") c.kind = Kind::CompareImage, name();
    else if (word == "split") {
      c.kind = Kind::Split;
      if (!(in >> c.value) || !(c.value >= 0.0f && c.value <= 1.0f)) fail("split expects a fraction from 0 to 1");
    } else if (word == "materials") {
      c.kind = Kind::Materials, name();
      if (!parse_material_override(c.arg)) fail("unknown materials '" + c.arg + "' (authored, white, mirror)");
    } else if (word == "tracer") {
      c.kind = Kind::Tracer, name();
      if (c.arg != "reference" && c.arg != "wavefront") fail("unknown tracer '" + c.arg + "'");
    } else if (word == "layers") {
      c.kind = Kind::Layers, name();
      if (c.arg == "stage") ints(1);
      else if (c.arg != "bounces" && c.arg != "none") fail("layers expects bounces, stage K or none");
    } else if (word == "open") c.kind = Kind::Open, name();
    else if (word == "export-vtk") c.kind = Kind::ExportVtk, name();
    else if (word == "save") c.kind = Kind::Save, name();
    else if (word == "screenshot") c.kind = Kind::Screenshot, name();
    else if (word == "quit") c.kind = Kind::Quit;
    else fail("unknown command '" + word + "'");
    std::string extra;
    if (in >> extra) fail("unexpected '" + extra + "' after " + word);
    commands.push_back(std::move(c));
  }
  return commands;
}

std::vector<ScriptCommand> load_script(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file + ": cannot read the script");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_script(text.str(), file);
}

}  // namespace pathlab::debug
