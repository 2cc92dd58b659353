// write_path_vtp for a build without VTK (-DPATHLAB_WITH_VTK=OFF).
#include "debugtools/vtk_export.h"

#include "core/error.h"

namespace pathlab {

bool vtk_export_available() { return false; }

void write_path_vtp(const std::filesystem::path& file, std::span<const PathLine>) {
  throw InputError(file.string() + ": this pathlab was built without VTK (-DPATHLAB_WITH_VTK=OFF), so it cannot "
                   "write .vtp files");
}

}  // namespace pathlab
