// The scene's surfaces as world-space triangles, for drawing beside recorded
// paths (trace-pixel --vtk-geometry, docs/path-vtk.md): either only the
// triangles the paths hit, or the whole scene when it has at most a stated
// number of triangles. Spheres are tessellated (kSphereRings x 2 kSphereRings
// latitude-longitude facets); instanced shapes are placed by their instance.
#pragma once

#include "core/math.h"
#include "core/scene.h"
#include "debugtools/path_recorder.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pathlab {

inline constexpr int kSphereRings = 16;
// Triangles of one tessellated sphere: two caps of fans and quads between.
inline constexpr std::size_t kSphereTriangles = 2 * 2 * kSphereRings * (kSphereRings - 1);

enum class GeometryScope : std::uint8_t { Hit, Scene };

struct GeometryTriangle {
  vec3 p[3];
  std::uint32_t shape = 0;
  std::int64_t prim = -1;        // the triangle of the shape's mesh; -1 for a sphere facet
  std::int64_t instance = -1;    // the instance that placed it; -1: placed in world space
  std::uint32_t material = 0;
  std::uint32_t hits = 0;        // hit events on it (a sphere: on the sphere) in the paths
};

struct SceneGeometry {
  std::vector<GeometryTriangle> triangles;
  std::size_t scene_triangles = 0;  // the whole scene's, spheres tessellated, instances expanded
  std::size_t limit = 0;
  GeometryScope asked = GeometryScope::Hit;
  bool complete = false;            // every scene triangle is in `triangles`
};

// The triangles of `scope` for the hit events of `paths`. Scope Scene gives
// every triangle if scene_triangles <= max_triangles, and otherwise falls
// back to the triangles hit (complete = false), which are always included.
SceneGeometry scene_geometry(const Scene& scene, std::span<const PathRecorder> paths, GeometryScope scope,
                             std::size_t max_triangles);

// The facets of a sphere (counter-clockwise seen from outside).
std::vector<std::array<vec3, 3>> tessellate_sphere(const vec3& center, float radius);

}  // namespace pathlab
