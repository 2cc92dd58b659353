// Tangents: the direction in a mesh's surface that anisotropic shading and
// normal maps measure angles from.
//
// Where they come from. A mesh keeps the tangents its file gave (glTF
// TANGENT). Otherwise the scene loader computes them only when something
// needs them ("model only what a scene requires"): a triangle shape with
// texture coordinates whose material is anisotropic (Disney anisotropic > 0,
// or textured) or has a normal map.
// Every other mesh has none, and its hits keep the frame built from the
// shading normal alone (Frame(ns)), bit for bit as before tangents existed.
//
// How they are computed (compute_tangents). In the spirit of MikkTSpace
// (Mikkelsen 2008): per triangle, the tangent dP/du and bitangent dP/dv from
// the texture-coordinate derivatives; each corner projects them onto its
// vertex normal's plane, normalises, and adds them weighted by the corner's
// angle; the sum is orthogonalised against the vertex normal (Gram-Schmidt)
// and normalised, and the handedness is w = sign(dot(cross(n, t), b)), so
// that the bitangent is w * cross(n, t) (glTF's convention).
//
// Where this differs from the real MikkTSpace, and why it is enough for now:
// - MikkTSpace splits a vertex whose corners disagree (a UV seam that
//   mirrors, opposite handedness, tangents far apart) into several, one
//   tangent each; here a vertex has one tangent, the average of its corners,
//   and the triangles on either side of a mirror seam share it (their
//   tangents may cancel to the fallback below). A UV seam itself is already
//   split: the loaders give corners with different texture coordinates
//   vertices of their own (core/mesh.h).
// - MikkTSpace also weights by the corner angle but keeps the magnitudes of
//   dP/du and dP/dv apart and treats degenerate triangles by borrowing from
//   neighbours; here a triangle of zero UV area contributes nothing, and a
//   vertex with no usable contribution gets the tangent of Frame(n) (its s
//   axis) with w = +1.
// An anisotropic highlight depends only on the tangent's direction up to its
// sign, so these differences move no highlight on a mesh with a continuous
// UV layout. A normal map is less forgiving: it must be decoded in exactly
// the frame it was baked in, so a mesh that brings its own (MikkTSpace-baked
// glTF TANGENT) keeps them and they are used; these computed ones may tilt a
// baked map's normals slightly differently at seams and on curved meshes
// (not yet compared against MikkTSpace). Debian ships no MikkTSpace
// package, hence this implementation.
#pragma once

#include "core/math.h"
#include "core/mesh.h"
#include "core/scene.h"

#include <cstdint>
#include <vector>

namespace pathlab {

// Per-vertex tangents (xyz unit, w = +-1) of a mesh with texture
// coordinates, as described above. The vertex normals are the mesh's, or the
// angle-weighted face normals (smooth_vertex_normals) of a flat mesh. Throws
// InputError when the mesh has no texture coordinates.
std::vector<vec4> compute_tangents(const TriangleMesh& mesh);

// True when `shape` needs computed tangents: a triangle mesh with texture
// coordinates, no tangents of its own, and an anisotropic material (or one
// whose anisotropy is textured) or a normal map.
bool needs_tangents(const Shape& shape, const Material& material);
// Computes the tangents of every shape of `scene` that needs_tangents(); the
// scene loader calls it once every shape is read.
void add_needed_tangents(Scene* scene);

}  // namespace pathlab
