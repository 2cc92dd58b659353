#include "core/tangents.h"

#include "core/error.h"
#include "core/geometry.h"
#include "core/material.h"

#include <cmath>

namespace pathlab {
namespace {

// `v` minus its component along the unit vector `n`.
dvec3 reject(const dvec3& v, const dvec3& n) { return v - glm::dot(v, n) * n; }

}  // namespace

std::vector<vec4> compute_tangents(const TriangleMesh& mesh) {
  if (!mesh.has_uvs()) throw InputError("compute_tangents: the mesh has no texture coordinates");
  const std::vector<vec3> normals = mesh.has_normals() ? mesh.normals : smooth_vertex_normals(mesh);
  std::vector<dvec3> t_sum(mesh.positions.size(), dvec3(0.0)), b_sum(mesh.positions.size(), dvec3(0.0));
  for (const glm::uvec3& tri : mesh.triangles) {
    const dvec3 p[3] = {dvec3(mesh.positions[tri.x]), dvec3(mesh.positions[tri.y]), dvec3(mesh.positions[tri.z])};
    const glm::dvec2 uv[3] = {glm::dvec2(mesh.uvs[tri.x]), glm::dvec2(mesh.uvs[tri.y]), glm::dvec2(mesh.uvs[tri.z])};
    // Solve [e1 e2] = [dP/du dP/dv] [d1 d2] for the two derivatives.
    const dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const glm::dvec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
    const double det = d1.x * d2.y - d2.x * d1.y;
    // Zero UV area: the texture coordinates say nothing about a direction.
    if (!(std::abs(det) > 0.0)) continue;
    const dvec3 dpdu = (d2.y * e1 - d1.y * e2) / det, dpdv = (d1.x * e2 - d2.x * e1) / det;
    if (!std::isfinite(glm::length(dpdu)) || !std::isfinite(glm::length(dpdv))) continue;
    for (int k = 0; k < 3; ++k) {
      const double angle = corner_angle(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
      // Each corner sees the derivatives in its own vertex's tangent plane,
      // as MikkTSpace does, so that a curved surface's corners agree.
      const dvec3 n(normals[tri[k]]);
      const dvec3 t = reject(dpdu, n), b = reject(dpdv, n);
      const double tl = glm::length(t), bl = glm::length(b);
      if (tl > 0.0) t_sum[tri[k]] += angle * (t / tl);
      if (bl > 0.0) b_sum[tri[k]] += angle * (b / bl);
    }
  }
  std::vector<vec4> tangents(mesh.positions.size());
  for (std::size_t v = 0; v < tangents.size(); ++v) {
    const dvec3 n(normals[v]);
    const dvec3 t = reject(t_sum[v], n);
    const double length = glm::length(t);
    if (!(length > 1e-12) || !std::isfinite(length)) {
      tangents[v] = vec4(Frame(normals[v]).s, 1.0f);  // no usable triangle: a tangent from the normal
      continue;
    }
    const dvec3 unit = t / length;
    tangents[v] = vec4(vec3(unit), glm::dot(glm::cross(n, unit), b_sum[v]) < 0.0 ? -1.0f : 1.0f);
  }
  return tangents;
}

bool needs_tangents(const Shape& shape, const Material& material) {
  const bool anisotropic = material.type == MaterialType::Disney &&
                           (material.disney.anisotropic > 0.0f || material.texture_of(MaterialParam::Anisotropic));
  return shape.kind == Shape::Kind::Triangles && shape.mesh.has_uvs() && shape.mesh.tangents.empty() &&
         (anisotropic || material.normal_map.has_value());
}

void add_needed_tangents(Scene* scene) {
  for (Shape& shape : scene->shapes)
    if (needs_tangents(shape, scene->materials[shape.material])) shape.mesh.tangents = compute_tangents(shape.mesh);
}

}  // namespace pathlab
