// OBJ meshes (core/mesh_io.cpp): load_mesh on the bytes written as a .obj
// file, with OBJ smoothing groups on (the default, the most code).
#include "fuzz/fuzz_target.h"

#include "core/mesh.h"

namespace pathlab::fuzz {

int obj(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path file = write_input("input.obj", data, size);
  return expect_input_error_only([&] {
    MeshLoadReport report;
    load_mesh(file, &report);
  });
}

}  // namespace pathlab::fuzz

PATHLAB_FUZZ_TARGET(obj)
