#include "analytic-scenes/edges.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace pathlab {

void EdgeList::segment(const dvec3& p0, const dvec3& p1) { arcs_.push_back({p0 - eye_, p1 - eye_, std::nullopt}); }

void EdgeList::mesh_edges(const Shape& shape) {
  const TriangleMesh& m = shape.mesh;
  // Each edge once, by its vertex indices, with the triangles that have it.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::size_t>> users;
  for (std::size_t i = 0; i < m.triangles.size(); ++i)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = m.triangles[i][e], b = m.triangles[i][(e + 1) % 3];
      users[{std::min(a, b), std::max(a, b)}].push_back(i);
    }
  const auto normal = [&](std::size_t i) {
    const glm::uvec3& t = m.triangles[i];
    const dvec3 p0(m.positions[t[0]]), p1(m.positions[t[1]]), p2(m.positions[t[2]]);
    const dvec3 n = glm::cross(p1 - p0, p2 - p0);
    const double len = glm::length(n);
    return len > 0.0 ? n / len : dvec3(0.0);
  };
  const auto material = [&](std::size_t i) { return m.face_material.empty() ? 0u : m.face_material[i]; };
  for (const auto& [edge, tris] : users) {
    // Inside one flat face: two triangles with the same vertices on the
    // edge (so the same interpolated attributes), the same plane, the same
    // side and the same material. The surface and everything read from it
    // are continuous there: nothing jumps.
    if (tris.size() == 2 && material(tris[0]) == material(tris[1]) &&
        glm::dot(normal(tris[0]), normal(tris[1])) > 1.0 - 1e-12)
      continue;
    segment(dvec3(m.positions[edge.first]), dvec3(m.positions[edge.second]));
  }
}

void EdgeList::sphere_silhouette(const dvec3& centre, double radius) {
  const dvec3 to_eye = eye_ - centre;
  const double d = glm::length(to_eye);
  if (!(d > radius)) return;  // the eye inside (or on) the sphere sees no silhouette
  // The points of tangency: a circle in the plane normal to to_eye, r^2 / d
  // from the centre towards the eye, of radius r sqrt(1 - r^2 / d^2).
  const dvec3 u = to_eye / d;
  const dvec3 c = centre + u * (radius * radius / d);
  const double rho = radius * std::sqrt(std::max(0.0, 1.0 - (radius / d) * (radius / d)));
  const dvec3 s = glm::normalize(std::abs(u.x) < 0.9 ? glm::cross(u, dvec3(1, 0, 0)) : glm::cross(u, dvec3(0, 1, 0)));
  const dvec3 t = glm::cross(u, s);
  constexpr int kPieces = 1024;
  const auto at = [&](double phi) { return c + rho * (std::cos(phi) * s + std::sin(phi) * t) - eye_; };
  for (int i = 0; i < kPieces; ++i) {
    const double p0 = 2.0 * M_PI * i / kPieces, p1 = 2.0 * M_PI * (i + 1) / kPieces;
    arcs_.push_back({at(p0), at(p1), at(0.5 * (p0 + p1))});
  }
}

void EdgeList::cone(const dvec3& axis, double cos_alpha) {
  const dvec3 u = glm::normalize(axis);
  const dvec3 s = glm::normalize(std::abs(u.x) < 0.9 ? glm::cross(u, dvec3(1, 0, 0)) : glm::cross(u, dvec3(0, 1, 0)));
  const dvec3 t = glm::cross(u, s);
  const double sin_alpha = std::sqrt(std::max(0.0, 1.0 - cos_alpha * cos_alpha));
  direction_curve([&](double phi) { return cos_alpha * u + sin_alpha * (std::cos(phi) * s + std::sin(phi) * t); }, 0.0,
                  2.0 * M_PI, 1024);
}

void EdgeList::direction_curve(const std::function<dvec3(double)>& dir, double s0, double s1, int pieces) {
  for (int i = 0; i < pieces; ++i) {
    const double a = s0 + (s1 - s0) * i / pieces, b = s0 + (s1 - s0) * (i + 1) / pieces;
    arcs_.push_back({dir(a), dir(b), dir(0.5 * (a + b))});
  }
}

void EdgeList::point_curve(const std::function<dvec3(double)>& p, double s0, double s1, int pieces) {
  direction_curve([&](double s) { return p(s) - eye_; }, s0, s1, pieces);
}

}  // namespace pathlab
