// glTF 2.0 (core/gltf_loader.cpp, gltf_validate.cpp): load_gltf on the bytes
// written as a .glb when they start with the binary magic "glTF", else as a
// .gltf, so one corpus mutates both. External buffers and images the input
// names are resolved in the work folder (and so are mostly missing).
#include "fuzz/fuzz_target.h"

#include "core/gltf_loader.h"

#include <cstring>

namespace pathlab::fuzz {

int gltf(const std::uint8_t* data, std::size_t size) {
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const std::filesystem::path file = write_input(binary ? "input.glb" : "input.gltf", data, size);
  return expect_input_error_only([&] { load_gltf(file); });
}

}  // namespace pathlab::fuzz

PATHLAB_FUZZ_TARGET(gltf)
