#include "core/data_dir.h"

#include <cstdlib>
#include <string>

#ifndef PATHLAB_DEFAULT_DATA_DIR
#error "PATHLAB_DEFAULT_DATA_DIR is set by core/CMakeLists.txt"
#endif

namespace pathlab {

std::filesystem::path data_directory() {
  const char* env = std::getenv("PATHLAB_DATA_DIR");
  if (env != nullptr && *env != '\0') return env;
  return PATHLAB_DEFAULT_DATA_DIR;
}

bool names_data_file(std::string_view name) { return name.starts_with(kDataPrefix); }

std::filesystem::path resolve_scene_path(const std::filesystem::path& folder, std::string_view name) {
  if (names_data_file(name)) return data_directory() / std::filesystem::path(name.substr(kDataPrefix.size()));
  return folder / std::filesystem::path(name);
}

std::string data_directory_hint() {
  const char* env = std::getenv("PATHLAB_DATA_DIR");
  const bool from_env = env != nullptr && *env != '\0';
  return "the data directory is " + data_directory().string() +
         (from_env ? " (from PATHLAB_DATA_DIR)" : " (set PATHLAB_DATA_DIR to use another)") +
         "; tools/fetch-data.sh fetches its files";
}

}  // namespace pathlab
