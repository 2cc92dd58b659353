#include "debugtools/scene_geometry.h"

#include <cmath>
#include <map>
#include <numbers>
#include <tuple>

namespace pathlab {
namespace {

vec3 place(const mat4* to_world, const vec3& p) { return to_world ? vec3(*to_world * vec4(p, 1.0f)) : p; }

std::size_t shape_triangles(const Shape& s) {
  return s.kind == Shape::Kind::Sphere ? kSphereTriangles : s.mesh.triangles.size();
}

// Appends shape `index` (every triangle, or only `prim` >= 0), placed by
// `instance` (-1: world space).
void add_shape(const Scene& scene, std::uint32_t index, std::int64_t instance, std::int64_t prim,
               std::vector<GeometryTriangle>& out) {
  const Shape& s = scene.shapes[index];
  const mat4* to_world = instance >= 0 ? &scene.instances[static_cast<std::size_t>(instance)].to_world : nullptr;
  GeometryTriangle t;
  t.shape = index;
  t.instance = instance;
  t.material = s.material;
  if (s.kind == Shape::Kind::Sphere) {
    for (const auto& f : tessellate_sphere(s.center, s.radius)) {
      for (int k = 0; k < 3; ++k) t.p[k] = place(to_world, f[static_cast<std::size_t>(k)]);
      out.push_back(t);
    }
    return;
  }
  const auto one = [&](std::size_t k) {
    const glm::uvec3 v = s.mesh.triangles[k];
    t.prim = static_cast<std::int64_t>(k);
    t.p[0] = place(to_world, s.mesh.positions[v.x]);
    t.p[1] = place(to_world, s.mesh.positions[v.y]);
    t.p[2] = place(to_world, s.mesh.positions[v.z]);
    out.push_back(t);
  };
  if (prim >= 0) {
    if (static_cast<std::size_t>(prim) < s.mesh.triangles.size()) one(static_cast<std::size_t>(prim));
    return;
  }
  for (std::size_t k = 0; k < s.mesh.triangles.size(); ++k) one(k);
}

}  // namespace

std::vector<std::array<vec3, 3>> tessellate_sphere(const vec3& center, float radius) {
  constexpr int rings = kSphereRings, segments = 2 * kSphereRings;
  const auto at = [&](int ring, int seg) {  // ring 0 = +z pole, `rings` = -z pole
    const float theta = std::numbers::pi_v<float> * static_cast<float>(ring) / rings;
    const float phi = 2.0f * std::numbers::pi_v<float> * static_cast<float>(seg % segments) / segments;
    return center + radius * vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  };
  std::vector<std::array<vec3, 3>> out;
  out.reserve(kSphereTriangles);
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const vec3 a = at(r, s), b = at(r + 1, s), c = at(r + 1, s + 1), d = at(r, s + 1);
      if (r > 0) out.push_back({a, b, d});           // not at the north pole (a == d there)
      if (r < rings - 1) out.push_back({d, b, c});   // not at the south pole (b == c there)
    }
  return out;
}

SceneGeometry scene_geometry(const Scene& scene, std::span<const PathRecorder> paths, GeometryScope scope,
                             std::size_t max_triangles) {
  SceneGeometry g;
  g.asked = scope;
  g.limit = max_triangles;
  for (const Shape& s : scene.shapes)
    if (!s.in_group) g.scene_triangles += shape_triangles(s);
  for (const Instance& inst : scene.instances)
    for (std::uint32_t s : scene.groups[inst.group].shapes) g.scene_triangles += shape_triangles(scene.shapes[s]);

  // Hits per (shape, instance, prim); a sphere counts as one prim (-1).
  std::map<std::tuple<std::uint32_t, std::int64_t, std::int64_t>, std::uint32_t> hits;
  for (const PathRecorder& path : paths)
    for (const PathEvent& e : path.events())
      if (const auto* h = std::get_if<HitEvent>(&e); h && h->shape < scene.shapes.size()) {
        const std::int64_t inst = h->instance == kNoInstance ? -1 : static_cast<std::int64_t>(h->instance);
        const std::int64_t prim =
            scene.shapes[h->shape].kind == Shape::Kind::Sphere ? -1 : static_cast<std::int64_t>(h->prim);
        ++hits[{h->shape, inst, prim}];
      }
  const auto hits_of = [&](const GeometryTriangle& t) {
    const auto it = hits.find({t.shape, t.instance, t.prim});
    return it == hits.end() ? 0u : it->second;
  };

  if (scope == GeometryScope::Scene && g.scene_triangles <= max_triangles) {
    g.triangles.reserve(g.scene_triangles);
    for (std::uint32_t s = 0; s < scene.shapes.size(); ++s)
      if (!scene.shapes[s].in_group) add_shape(scene, s, -1, -1, g.triangles);
    for (std::size_t i = 0; i < scene.instances.size(); ++i)
      for (std::uint32_t s : scene.groups[scene.instances[i].group].shapes)
        add_shape(scene, s, static_cast<std::int64_t>(i), -1, g.triangles);
    for (GeometryTriangle& t : g.triangles) t.hits = hits_of(t);
    g.complete = true;
    return g;
  }
  for (const auto& [key, count] : hits) {
    const auto [shape, inst, prim] = key;
    const std::size_t before = g.triangles.size();
    add_shape(scene, shape, inst, prim, g.triangles);
    for (std::size_t k = before; k < g.triangles.size(); ++k) g.triangles[k].hits = count;
  }
  g.complete = g.triangles.size() == g.scene_triangles;
  return g;
}

}  // namespace pathlab
