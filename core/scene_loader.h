// Reading scene files (format: docs/scene-format.md). Every problem is an
// InputError "<file>:<line>:<column>: <where in the scene>: <problem>".
#pragma once

#include "core/scene.h"

#include <filesystem>
#include <string_view>

namespace pathlab {

inline constexpr int kSceneFormatVersion = 1;

// Loads a scene file; mesh paths are relative to its folder. A .gltf or .glb
// file is a scene of its own (load_gltf_scene in gltf_loader.h).
Scene load_scene(const std::filesystem::path& file);

// Parses scene text. `file` names it in messages and anchors relative mesh
// paths (its parent folder); it need not exist.
Scene parse_scene(std::string_view text, const std::filesystem::path& file);

// The built-in Cornell box (scenes/cornell-box.json, compiled in).
Scene builtin_cornell_box();
std::string_view builtin_cornell_box_text();

}  // namespace pathlab
