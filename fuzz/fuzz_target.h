// One fuzz target = one function `int pathlab::fuzz::<name>(data, size)`
// that feeds the bytes to a loader the way a user's file would reach it.
// Bad input must come back as InputError (core/error.h: exit code 2, one
// message); the target swallows that and returns 0. Anything else — another
// exception, a crash, a sanitizer report, a leak — is a finding.
//
// The same sources build two ways (fuzz/CMakeLists.txt):
//  - into pathlab_fuzz_targets, which tests/test_fuzz_corpus.cpp links to
//    replay every file of fuzz/corpus/<name>/ in the normal (gcc) build;
//  - with PATHLAB_LIBFUZZER defined, one libFuzzer executable per target
//    (PATHLAB_FUZZ=ON, clang only), where PATHLAB_FUZZ_TARGET also defines
//    LLVMFuzzerTestOneInput.
#pragma once

#include "core/error.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

namespace pathlab::fuzz {

using Target = int (*)(const std::uint8_t* data, std::size_t size);

// A folder of this process under the system's temporary folder, made on first
// use and removed at exit, in which a target writes its input under the file
// name a loader expects (loaders take paths; writing a small file costs
// microseconds). PATHLAB_DATA_DIR is pointed at an empty folder inside it, so
// a fuzzed "$data/..." name never reaches the real (large) test data.
const std::filesystem::path& work_folder();

// Writes `size` bytes to work_folder()/name, replacing it, and returns the path.
std::filesystem::path write_input(std::string_view name, const std::uint8_t* data, std::size_t size);

void report_outcome(const char* what);  // one line on stderr

// True when PATHLAB_FUZZ_VERBOSE is set: targets then print the InputError
// each input gets (to see what a seed or a crasher reaches).
bool verbose();

// Calls `load()`; an InputError is the expected answer to bad input and is
// swallowed. Everything else propagates (a finding).
template <typename Load>
int expect_input_error_only(Load&& load) {
  try {
    load();
    if (verbose()) report_outcome("loaded");
  } catch (const InputError& e) {
    if (verbose()) report_outcome(e.what());
  }
  return 0;
}

}  // namespace pathlab::fuzz

#ifdef PATHLAB_LIBFUZZER
#define PATHLAB_FUZZ_TARGET(name)                                                                \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {           \
    return ::pathlab::fuzz::name(data, size);                                                    \
  }
#else
#define PATHLAB_FUZZ_TARGET(name)
#endif

namespace pathlab::fuzz {

// The targets (one source each in fuzz/, corpus in fuzz/corpus/<name>/).
int scene(const std::uint8_t* data, std::size_t size);         // scene JSON: parse_scene
int ply(const std::uint8_t* data, std::size_t size);           // load_mesh on a .ply
int obj(const std::uint8_t* data, std::size_t size);           // load_mesh on an .obj
int gltf(const std::uint8_t* data, std::size_t size);          // load_gltf on a .glb ("glTF" magic) or .gltf
int partial_film(const std::uint8_t* data, std::size_t size);  // read_partial_film, checksum appended
int envmap(const std::uint8_t* data, std::size_t size);        // load_environment_map (read_image, OIIO)

}  // namespace pathlab::fuzz
