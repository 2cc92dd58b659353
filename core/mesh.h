// Triangle meshes as loaded from disk, before they enter a Scene.
#pragma once

#include "core/math.h"

#include <cstddef>
#include <filesystem>
#include <vector>

namespace pathlab {

struct TriangleMesh {
  std::vector<vec3> positions;
  std::vector<glm::uvec3> triangles;  // indices into `positions`
};

struct MeshLoadReport {
  std::size_t faces_in_file = 0;         // PLY: faces as stored; OBJ: triangles after tinyobjloader
  std::size_t triangles_loaded = 0;      // after fan triangulation and dropping
  std::size_t degenerate_dropped = 0;    // zero-area or repeated-index triangles
};

// Loads a triangle mesh from Wavefront OBJ (via tinyobjloader) or PLY
// (ASCII, binary little- or big-endian). Either may be gzip-compressed
// (`.obj.gz`, `.ply.gz`); the format is chosen by the extension before `.gz`.
// PLY polygons are fan-triangulated (convex polygons assumed); OBJ polygons
// are triangulated by tinyobjloader. Degenerate triangles (repeated indices or
// zero area) are dropped and counted in `report`.
//
// Throws InputError naming the file and the problem for: a missing or
// unreadable file, an unknown extension, a malformed header or body, a
// truncated file, an index out of range, a NaN or infinite vertex
// coordinate, and a mesh with no usable triangle.
TriangleMesh load_mesh(const std::filesystem::path& file, MeshLoadReport* report = nullptr);

// Reads a whole file, transparently decompressing gzip. Throws InputError.
std::vector<char> read_file_maybe_gz(const std::filesystem::path& file);

}  // namespace pathlab
