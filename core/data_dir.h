// Where scenes find the data they do not carry: the meshes and environment
// maps that tools/fetch-data.sh fetches from package registries. A scene names
// such a file "$data/meshes/bunny.ply" (docs/scene-format.md); every other
// relative path is relative to the scene file's folder.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace pathlab {

// The prefix that names the data directory in a scene's file names.
inline constexpr std::string_view kDataPrefix = "$data/";

// $PATHLAB_DATA_DIR when it is set and not empty, otherwise the folder this
// build was configured with (the CMake cache variable PATHLAB_DATA_DIR, by
// default data/ in the source tree).
std::filesystem::path data_directory();

// True when `name` starts with "$data/".
bool names_data_file(std::string_view name);

// A file name as a scene writes it: "$data/x" is x in data_directory(), a
// relative name is relative to `folder`, an absolute one stays as it is.
std::filesystem::path resolve_scene_path(const std::filesystem::path& folder, std::string_view name);

// For a message about a missing "$data/..." file: where the data directory is
// and how to fill it.
std::string data_directory_hint();

}  // namespace pathlab
