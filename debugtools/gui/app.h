// pathlab-debug: the window (GLFW + OpenGL 3 + Dear ImGui) around a Session.
// The image starts 1:1 at the window's top-left corner (scaled down only if
// it would not fit a 1600x1000 window), the panel to its right; the wheel
// zooms about the cursor, a drag pans, the split view puts another render or
// image file right of a draggable divider (docs/pathlab-debug.md).
#pragma once

#include "debugtools/gui/session.h"

#include <iosfwd>
#include <string>

namespace pathlab::debug {

struct AppOptions {
  SessionSettings session;
  std::string script;      // --script FILE (script.h); empty: interactive
  std::string screenshot;  // --screenshot PNG written when the window closes
  std::string view = "beauty";
  float exposure = 0.0f;
};

// Runs the viewer until the window closes or the script quits. Returns the
// exit code: 0, 2 for bad input (scene, script, a failing script command),
// 3 when no window can be opened. Messages go to `err`.
int run_app(const AppOptions& options, std::ostream& err);

// Overlay colours (RGBA bytes): the path polyline and its vertices, and
// shadow rays that reached / missed their light. Tests look for them.
inline constexpr unsigned char kPathColour[4] = {0, 255, 0, 255};
inline constexpr unsigned char kVertexColour[4] = {255, 255, 0, 255};
inline constexpr unsigned char kShadowVisibleColour[4] = {0, 200, 255, 255};
inline constexpr unsigned char kShadowBlockedColour[4] = {255, 60, 60, 255};

}  // namespace pathlab::debug
