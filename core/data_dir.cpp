#include "core/data_dir.h"

#include <cstdlib>
#include <string>

#ifndef PATHLAB_DEFAULT_DATA_DIR
#error "PATHLAB_DEFAULT_DATA_DIR is set by core/CMakeLists.txt"
#endif

namespace pathlab {
namespace {

// $PATHLAB_DATA_DIR, or null when it is unset or empty.
const char* data_directory_from_environment() {
  const char* env = std::getenv("PATHLAB_DATA_DIR");
  return env != nullptr && *env != '\0' ? env : nullptr;
}

}  // namespace

std::filesystem::path data_directory() {
  const char* env = data_directory_from_environment();
  return env != nullptr ? std::filesystem::path(env) : std::filesystem::path(PATHLAB_DEFAULT_DATA_DIR);
}

bool names_data_file(std::string_view name) { return name.starts_with(kDataPrefix); }

std::filesystem::path resolve_scene_path(const std::filesystem::path& folder, std::string_view name) {
  if (names_data_file(name)) return data_directory() / std::filesystem::path(name.substr(kDataPrefix.size()));
  return folder / std::filesystem::path(name);
}

std::string data_directory_hint() {
  return "the data directory is " + data_directory().string() +
         (data_directory_from_environment() != nullptr ? " (from PATHLAB_DATA_DIR)" : " (set PATHLAB_DATA_DIR to use another)") +
         "; tools/fetch-data.sh fetches its files";
}

}  // namespace pathlab
