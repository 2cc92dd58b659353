// Scene files (core/scene_loader*.cpp) from memory: parse_scene, as if the
// text were work_folder()/scene.json. The folder holds a tiny OBJ, PLY and
// Radiance HDR image, so a scene that names "tri.obj", "tri.ply" or
// "sky.hdr" reaches the shape and light code with a real file.
#include "fuzz/fuzz_target.h"

#include "core/scene_loader.h"

#include <string>

namespace pathlab::fuzz {
namespace {

void write_text(std::string_view name, std::string_view text) {
  write_input(name, reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
}

bool write_side_files() {
  write_text("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
  write_text("tri.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  // 2x1 Radiance RGBE, flat (too narrow for run-length rows).
  write_text("sky.hdr", std::string("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n") +
                            std::string("\x80\x80\x80\x81\x40\x40\x40\x81", 8));
  return true;
}

}  // namespace

int scene(const std::uint8_t* data, std::size_t size) {
  static const bool ready = write_side_files();
  (void)ready;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  return expect_input_error_only([&] { parse_scene(text, work_folder() / "scene.json"); });
}

}  // namespace pathlab::fuzz

PATHLAB_FUZZ_TARGET(scene)
