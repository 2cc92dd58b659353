// Triangle meshes as loaded from disk, before they enter a Scene.
#pragma once

#include "core/math.h"

#include <cstddef>
#include <cstdint>
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
  // The file's material names per triangle (OBJ `usemtl`), or both empty.
  // face_material[t] indexes material_names, or is kNoFileMaterial for a
  // face before the first `usemtl`. Only load_mesh fills them; a scene's
  // shapes never carry them (the scene loader splits such a mesh into one
  // shape per material, split_by_face_material).
  static constexpr std::uint16_t kNoFileMaterial = 0xffff;
  std::vector<std::uint16_t> face_material;
  std::vector<std::string> material_names;  // in the order of first use

  bool has_normals() const { return !normals.empty(); }
  bool has_uvs() const { return !uvs.empty(); }
  // The texture coordinates at barycentrics b = (b1, b2) of triangle `t`, or
  // b itself on a mesh without them: what shading, alpha tests and light
  // samples all read a triangle's textures at. Generic code
  // (core/simd/texture_inputs-inl.h uv_at) that the wavefront's lanes call too.
  vec2 uv_at(std::uint32_t t, vec2 b) const;
  bool has_face_materials() const { return !face_material.empty(); }
};

struct MeshLoadOptions {
  // OBJ smoothing groups (`s`) become vertex normals when the file has no
  // `vn`: "normals": "file". Off for "flat" and "smooth", which replace
  // the normals anyway (and "smooth" must not see vertices split by group).
  bool smoothing_groups = true;
};

struct MeshLoadReport {
  std::size_t faces_in_file = 0;         // PLY: faces as stored; OBJ: triangles after tinyobjloader
  std::size_t triangles_loaded = 0;      // after fan triangulation and dropping
  std::size_t degenerate_dropped = 0;    // zero-area or repeated-index triangles
  // What the file holds that pathlab does not read (vertex colours, the
  // content of an OBJ material library, ...), one phrase each, for one warning.
  std::vector<std::string> ignored;
};

// Angle-weighted vertex normals (Thürmer & Wüthrich 1998) from the
// triangles: what "normals": "smooth" gives a mesh without normals. A
// vertex no triangle uses gets the normal (0, 0, 1).
std::vector<vec3> smooth_vertex_normals(const TriangleMesh& mesh);

// One part per material slot that some triangle uses (kNoFileMaterial
// first, then in the order of material_names), each with only the vertices
// its triangles use, in their order, and without face materials. A mesh
// without face materials comes back whole as one kNoFileMaterial part.
std::vector<std::pair<std::uint16_t, TriangleMesh>> split_by_face_material(TriangleMesh mesh);

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
// OBJ `usemtl` names become TriangleMesh::face_material (the .mtl file is
// not read: the scene gives the materials). OBJ smoothing groups, in a file
// without `vn` and with `options.smoothing_groups`, become vertex normals:
// the faces of one non-zero group share angle-weighted normals at shared
// positions (as smooth_vertex_normals); faces of group 0 (`s off`) get
// their face normal at each corner, so they shade flat. A position where
// faces of different groups meet gets one vertex per group.
//
// Throws InputError naming the file and the problem for: a missing or
// unreadable file, an unknown extension, a malformed header or body, a
// truncated file, an index out of range, a NaN or infinite vertex
// coordinate, normal or texture coordinate, a zero-length normal, and a mesh
// with no usable triangle.
TriangleMesh load_mesh(const std::filesystem::path& file, MeshLoadReport* report = nullptr,
                       const MeshLoadOptions& options = {});

// Reads a whole file, transparently decompressing gzip. Throws InputError.
std::vector<char> read_file_maybe_gz(const std::filesystem::path& file);

}  // namespace pathlab
