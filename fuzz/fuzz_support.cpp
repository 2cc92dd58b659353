#include "fuzz/fuzz_target.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace pathlab::fuzz {
namespace fs = std::filesystem;

namespace {

struct WorkFolder {
  fs::path path;
  WorkFolder() : path(fs::temp_directory_path() / ("pathlab-fuzz-" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path / "data");
    ::setenv("PATHLAB_DATA_DIR", (path / "data").c_str(), 1);
  }
  ~WorkFolder() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

}  // namespace

const fs::path& work_folder() {
  static const WorkFolder folder;
  return folder.path;
}

bool verbose() {
  static const bool on = std::getenv("PATHLAB_FUZZ_VERBOSE") != nullptr;
  return on;
}

void report_outcome(const char* what) { std::fprintf(stderr, "fuzz: %s\n", what); }

fs::path write_input(std::string_view name, const std::uint8_t* data, std::size_t size) {
  const fs::path file = work_folder() / std::string(name);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) throw std::runtime_error("fuzz: cannot write " + file.string());
  return file;
}

}  // namespace pathlab::fuzz
