// Paths as VTK XML PolyData (.vtp), for ParaView: one polyline per line of
// path_geometry.h, with point and cell data arrays (docs/path-vtk.md).
// Built only with VTK (PATHLAB_WITH_VTK); without it write_path_vtp throws.
#pragma once

#include "debugtools/path_geometry.h"

#include <filesystem>
#include <span>

namespace pathlab {

// Writes `lines` with VTK's own XML writer to a temporary file beside `file`
// and renames it into place. Throws InputError if `file` cannot be written
// there, SystemError if VTK fails; never leaves a partial file.
void write_path_vtp(const std::filesystem::path& file, std::span<const PathLine> lines);

// True if this build can write .vtp files.
bool vtk_export_available();

}  // namespace pathlab
