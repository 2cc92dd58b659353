#include "analytic-scenes/room.h"

#include "core/error.h"
#include "core/geometry.h"

#include <map>
#include <tuple>

namespace pathlab::analytic {

void refuse(const Scene& scene, std::string_view model, const std::string& problem) {
  const std::string where = scene.file.empty() ? "<built-in " + scene.name + ">" : scene.file.string();
  throw InputError(where + ": analytic model '" + std::string(model) + "': " + problem);
}

bool is_closed(const Shape& shape) {
  if (shape.kind == Shape::Kind::Sphere) return true;
  // Undirected edges keyed by their endpoints' positions (boxes and
  // rectangles have one set of vertices per face).
  using Key = std::tuple<float, float, float>;
  auto key = [](const vec3& p) { return Key(p.x, p.y, p.z); };
  std::map<std::pair<Key, Key>, int> edges;
  const auto& m = shape.mesh;
  for (const glm::uvec3& t : m.triangles)
    for (int e = 0; e < 3; ++e) {
      Key a = key(m.positions[t[e]]), b = key(m.positions[t[(e + 1) % 3]]);
      if (b < a) std::swap(a, b);
      ++edges[{a, b}];
    }
  for (const auto& [edge, count] : edges)
    if (count != 2) return false;
  return !edges.empty();
}

namespace {

// Signed volume enclosed by a closed mesh, positive for outward winding.
double signed_volume(const TriangleMesh& m) {
  double v = 0.0;
  for (const glm::uvec3& t : m.triangles)
    v += glm::dot(dvec3(m.positions[t.x]), glm::cross(dvec3(m.positions[t.y]), dvec3(m.positions[t.z])));
  return v / 6.0;
}

}  // namespace

std::optional<double> hit_triangle(const dvec3& o, const dvec3& d, const dvec3& p0, const dvec3& p1, const dvec3& p2) {
  // Möller-Trumbore.
  const dvec3 e1 = p1 - p0, e2 = p2 - p0, q = glm::cross(d, e2);
  const double det = glm::dot(e1, q);
  if (det == 0.0) return std::nullopt;
  const dvec3 s = o - p0;
  const double u = glm::dot(s, q) / det;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  const dvec3 r = glm::cross(s, e1);
  const double v = glm::dot(d, r) / det, t = glm::dot(e2, r) / det;
  if (v < 0.0 || u + v > 1.0 || t <= 0.0) return std::nullopt;
  return t;
}

bool contains(const Shape& shape, const vec3& p) {
  if (shape.kind == Shape::Kind::Sphere) return glm::length(dvec3(p) - dvec3(shape.center)) < shape.radius;
  // Parity along an arbitrary, irrational-looking direction (edges and
  // vertices are hit with probability zero).
  const dvec3 d = glm::normalize(dvec3(0.5773, 0.6181, 0.5329));
  int crossings = 0;
  for (const glm::uvec3& t : shape.mesh.triangles)
    crossings += hit_triangle(dvec3(p), d, dvec3(shape.mesh.positions[t.x]), dvec3(shape.mesh.positions[t.y]),
                              dvec3(shape.mesh.positions[t.z]))
                     .has_value();
  return crossings % 2 == 1;
}

bool front_faces_inwards(const Shape& shape) {
  if (shape.kind == Shape::Kind::Sphere) return shape.flip_normals;
  const bool outward_winding = signed_volume(shape.mesh) > 0.0;
  return outward_winding == shape.flip_normals;
}

bool emits_inwards(const Shape& shape, const Material& material) {
  return material.two_sided_emission || front_faces_inwards(shape);
}

Spectrum reflectance_inside(const Shape& shape, const Material& material) {
  return material.one_sided && !front_faces_inwards(shape) ? Spectrum(0.0f) : material.albedo;
}

std::optional<double> hit_sphere(const vec3& center, float radius, const Ray& ray) {
  const dvec3 oc = dvec3(ray.origin) - dvec3(center), d = glm::normalize(dvec3(ray.dir));
  const double b = glm::dot(oc, d), c = glm::dot(oc, oc) - double(radius) * radius;
  const double disc = b * b - c;
  if (disc < 0.0) return std::nullopt;
  const double s = std::sqrt(disc);
  if (-b - s > 0.0) return -b - s;
  if (-b + s > 0.0) return -b + s;
  return std::nullopt;
}

}  // namespace pathlab::analytic
