// Paths as VTK XML PolyData (.vtp), for ParaView: one polyline per line of
// path_geometry.h, with point and cell data arrays (docs/path-vtk.md).
// Built only with VTK (PATHLAB_WITH_VTK); without it write_path_vtp throws.
#pragma once

#include "debugtools/path_geometry.h"
#include "debugtools/scene_geometry.h"

#include <filesystem>
#include <span>

namespace pathlab {

// Writes `lines` with VTK's own XML writer to a temporary file beside `file`
// and renames it into place. Throws InputError if `file` cannot be written
// there, SystemError if VTK fails; never leaves a partial file.
void write_path_vtp(const std::filesystem::path& file, std::span<const PathLine> lines);

// Writes scene triangles (scene_geometry.h) as VTK XML PolyData polygons,
// three points each, with the cell arrays shape, prim, instance, material and
// hits and the field arrays scene_triangles, limit, complete and scope
// (docs/path-vtk.md). Throws and leaves no partial file, as write_path_vtp.
void write_geometry_vtp(const std::filesystem::path& file, const SceneGeometry& geometry);

// Where write_paths_and_geometry puts the geometry and the multiblock file
// for paths written to `vtp`: out.vtp -> out.geometry.vtp and out.vtm.
std::filesystem::path geometry_vtp_path(const std::filesystem::path& vtp);
std::filesystem::path multiblock_path(const std::filesystem::path& vtp);

// Writes the paths to `vtp`, the geometry beside it (geometry_vtp_path) and
// a VTK multiblock file (multiblock_path: blocks "paths" and "geometry",
// referring to the two by relative name) that opens both in ParaView at once.
void write_paths_and_geometry(const std::filesystem::path& vtp, std::span<const PathLine> lines,
                              const SceneGeometry& geometry);

// True if this build can write .vtp files.
bool vtk_export_available();

}  // namespace pathlab
