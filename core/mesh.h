// Triangle meshes as loaded from disk, before they enter a Scene.
#pragma once

#include "core/math.h"

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace pathlab {

// Vertex attributes are per vertex, indexed like `positions`, and either
// absent (empty) or one per vertex. A corner that needs an attribute another
// corner of the same position does not share gets a vertex of its own.
struct TriangleMesh {
  TriangleMesh() = default;
  TriangleMesh(std::vector<vec3> p, std::vector<glm::uvec3> t, std::vector<vec3> n = {}, std::vector<vec2> uv = {})
      : positions(std::move(p)), triangles(std::move(t)), normals(std::move(n)), uvs(std::move(uv)) {}

  std::vector<vec3> positions;
  std::vector<glm::uvec3> triangles;  // indices into `positions`
  std::vector<vec3> normals;          // unit shading normals, or empty (flat shading)
  std::vector<vec2> uvs;              // texture coordinates (origin bottom-left, v up), or empty
  // Unit tangents (xyz) and the bitangent's handedness (w = +-1: bitangent =
  // w * cross(normal, tangent)), or empty. Only glTF files bring them today.
  std::vector<glm::vec4> tangents;

  bool has_normals() const { return !normals.empty(); }
  bool has_uvs() const { return !uvs.empty(); }
};

struct MeshLoadReport {
  std::size_t faces_in_file = 0;         // PLY: faces as stored; OBJ: triangles after tinyobjloader
  std::size_t triangles_loaded = 0;      // after fan triangulation and dropping
  std::size_t degenerate_dropped = 0;    // zero-area or repeated-index triangles
  // What the file holds that pathlab does not read (vertex colours, OBJ
  // materials and smoothing groups, ...), one phrase each, for one warning.
  std::vector<std::string> ignored;
};

// Angle-weighted vertex normals (Thürmer & Wüthrich 1998) from the
// triangles: what "normals": "smooth" gives a mesh without normals. A
// vertex no triangle uses gets the normal (0, 0, 1).
std::vector<vec3> smooth_vertex_normals(const TriangleMesh& mesh);

// Loads a triangle mesh from Wavefront OBJ (via tinyobjloader) or PLY
// (ASCII, binary little- or big-endian). Either may be gzip-compressed
// (`.obj.gz`, `.ply.gz`); the format is chosen by the extension before `.gz`.
// PLY polygons are fan-triangulated (convex polygons assumed); OBJ polygons
// are triangulated by tinyobjloader. Degenerate triangles (repeated indices or
// zero area) are dropped and counted in `report`.
//
// Vertex normals (PLY nx ny nz, OBJ vn) and texture coordinates (PLY u v,
// s t or texture_u texture_v; OBJ vt) are read when the file has them. An OBJ
// face corner without a normal in a mesh that has some gets its face's
// normal.
//
// Throws InputError naming the file and the problem for: a missing or
// unreadable file, an unknown extension, a malformed header or body, a
// truncated file, an index out of range, a NaN or infinite vertex
// coordinate, normal or texture coordinate, a zero-length normal, and a mesh
// with no usable triangle.
TriangleMesh load_mesh(const std::filesystem::path& file, MeshLoadReport* report = nullptr);

// Reads a whole file, transparently decompressing gzip. Throws InputError.
std::vector<char> read_file_maybe_gz(const std::filesystem::path& file);

}  // namespace pathlab
