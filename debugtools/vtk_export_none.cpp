// write_path_vtp for a build without VTK (-DPATHLAB_WITH_VTK=OFF).
#include "debugtools/vtk_export.h"

#include "core/error.h"

namespace pathlab {

bool vtk_export_available() { return false; }

void write_path_vtp(const std::filesystem::path& file, std::span<const PathLine>) {
  throw InputError(file.string() + ": this pathlab was built without VTK (-DPATHLAB_WITH_VTK=OFF), so it cannot "
                   "write .vtp files");
}

void write_geometry_vtp(const std::filesystem::path& file, const SceneGeometry&) { write_path_vtp(file, {}); }

std::filesystem::path geometry_vtp_path(const std::filesystem::path& vtp) {
  return std::filesystem::path(vtp).replace_extension(".geometry.vtp");
}
std::filesystem::path multiblock_path(const std::filesystem::path& vtp) {
  return std::filesystem::path(vtp).replace_extension(".vtm");
}
void write_paths_and_geometry(const std::filesystem::path& vtp, std::span<const PathLine>, const SceneGeometry&) {
  write_path_vtp(vtp, {});
}

}  // namespace pathlab
