// The scripted mode of pathlab-debug (--script FILE): one command a line,
// '#' starts a comment. The app runs them in order, one per frame, through
// the same code paths as the mouse and the panel (hover and click move
// ImGui's mouse to the pixel's centre and press the button for one frame):
//
//   wait-spp N            wait until the render has N samples per pixel (or its target)
//   hover X Y             point at pixel (X, Y): the readout panel shows it
//   click X Y             click pixel (X, Y): retrace the chosen sample, draw its path
//   sample S              the sample a click retraces (default 0)
//   view NAME             any layer of the render (beauty, albedo, normal, depth, material,
//                         variance, pathlength, nonfinite, samples, ...) or nan (the NaN/Inf map)
//   scale NAME            how the layer is mapped: tone, normal, id, linear, log (views.h)
//   exposure STOPS        exposure of the view
//   mouse WX WY           move the mouse to window position (WX, WY) (hover by window position)
//   wheel WX WY N         turn the mouse wheel N notches (negative: out) at (WX, WY): zoom about it
//   drag WX WY DX DY      drag with the left button from (WX, WY) by (DX, DY): pans the image,
//                         or moves the split view's divider when it starts on it
//   fit                   the "Fit" button: the whole image in the window
//   actual-size           the "1:1" button: one image pixel per screen pixel
//   readout PATH          write the pixel panel's text (the buffer values under the mouse) to PATH
//   next-nan              the "Next NaN/Inf" button: jump to the next NaN/Inf sample and retrace it
//   compare tracer        split view: this render | the same scene and seed with the other tracer
//   compare-image PATH    split view: this render | an image file (every EXR layer)
//   compare off           back to one image
//   split F               put the split view's divider at fraction F (0..1) of the image area
//   materials NAME        authored, white, mirror (restarts the render)
//   tracer NAME           reference, wavefront (restarts the render)
//   layers bounces        add the per-bounce layers L0.bsdf .. Lrest.nee (restarts the render)
//   layers stage K        add the wavefront's stage buffers at vertex K, stageK.* (restarts)
//   layers none           neither
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
  enum class Kind { WaitSpp, Hover, Click, Sample, View, Scale, Exposure, Materials, Tracer, Open, ExportVtk, Save,
                    Screenshot, Mouse, Wheel, Drag, Fit, ActualSize, Readout, NextNan, Compare, CompareImage, Split,
                    Layers, Quit };
  Kind kind = Kind::Quit;
  int x = 0, y = 0;      // hover, click, mouse, wheel, drag; x is N for wait-spp, S for sample, K for layers stage
  int dx = 0, dy = 0;    // drag; dx is N for wheel
  float value = 0.0f;    // exposure, split
  std::string arg;       // names and paths
  std::string where;     // "file:line" for messages
};

// Parses a script. Throws InputError naming file:line for an unknown command
// or bad arguments.
std::vector<ScriptCommand> parse_script(const std::string& text, const std::string& file);
std::vector<ScriptCommand> load_script(const std::string& file);

}  // namespace pathlab::debug
