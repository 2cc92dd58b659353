// The scripted mode of pathlab-debug (--script FILE): one command a line,
// '#' starts a comment. The app runs them in order, one per frame, through
// the same code paths as the mouse and the panel (hover and click move
// ImGui's mouse to the pixel's centre and press the button for one frame):
//
//   wait-spp N            wait until the render has N samples per pixel (or its target)
//   hover X Y             point at pixel (X, Y): the readout panel shows it
//   click X Y             click pixel (X, Y): retrace the chosen sample, draw its path
//   sample S              the sample a click retraces (default 0)
//   view NAME             beauty, albedo, normal, depth, material, variance, pathlength, nan
//   exposure STOPS        exposure of the view
//   materials NAME        authored, white, mirror (restarts the render)
//   tracer NAME           reference, wavefront (restarts the render)
//   open PATH             open a scene file (restarts the render)
//   export-vtk PATH       the "Export VTK" button
//   save PATH             the "Save image" button (.exr or .png)
//   screenshot PATH       the window as it is now, as PNG
//   quit                  close the window
#pragma once

#include <string>
#include <vector>

namespace pathlab::debug {

struct ScriptCommand {
  enum class Kind { WaitSpp, Hover, Click, Sample, View, Exposure, Materials, Tracer, Open, ExportVtk, Save,
                    Screenshot, Quit };
  Kind kind = Kind::Quit;
  int x = 0, y = 0;      // hover, click; x is N for wait-spp and S for sample
  float value = 0.0f;    // exposure
  std::string arg;       // names and paths
  std::string where;     // "file:line" for messages
};

// Parses a script. Throws InputError naming file:line for an unknown command
// or bad arguments.
std::vector<ScriptCommand> parse_script(const std::string& text, const std::string& file);
std::vector<ScriptCommand> load_script(const std::string& file);

}  // namespace pathlab::debug
