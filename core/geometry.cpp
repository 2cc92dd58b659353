#include "core/geometry.h"

#include "core/error.h"
#include "core/sampling.h"
#include "core/scene_limits.h"
#include "core/simd/width1.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace pathlab {

std::size_t transform_mesh(TriangleMesh* mesh, const mat4& xf) {
  for (vec3& p : mesh->positions) p = vec3(xf * vec4(p, 1.0f));
  // Normals by the inverse transpose, in double so that a strong
  // non-uniform scale does not lose them; a normal the transform squashes to
  // nothing (a singular matrix) is caught with the triangles it belongs to.
  if (mesh->has_normals()) {
    const glm::dmat3 to_normal = glm::transpose(glm::inverse(glm::dmat3(mat3(xf))));
    for (vec3& n : mesh->normals) {
      const dvec3 m = to_normal * dvec3(n);
      const double length = glm::length(m);
      n = length > 0.0 && std::isfinite(length) ? vec3(m / length) : vec3(0.0f, 0.0f, 1.0f);
    }
  }
  const bool mirrors = glm::determinant(mat3(xf)) < 0.0f;
  // Tangents lie in the surface, so they move with it (the plain matrix).
  // The bitangent is w * cross(n, t): a mirror flips cross(n', t') against
  // the mirrored bitangent, so w flips too.
  for (vec4& t : mesh->tangents) {
    const dvec3 m = glm::dmat3(mat3(xf)) * dvec3(vec3(t));
    const double length = glm::length(m);
    const vec3 dir = length > 0.0 && std::isfinite(length) ? vec3(m / length) : vec3(1.0f, 0.0f, 0.0f);
    t = vec4(dir, mirrors ? -t.w : t.w);
  }
  // A mirroring transform turns counter-clockwise into clockwise: swap two
  // indices so the front side stays the side the normal was on.
  if (mirrors)
    for (glm::uvec3& t : mesh->triangles) std::swap(t.y, t.z);
  std::vector<glm::uvec3> kept;
  kept.reserve(mesh->triangles.size());
  for (std::uint32_t i = 0; i < mesh->triangles.size(); ++i)
    if (triangle_area(*mesh, i) > 0.0f) kept.push_back(mesh->triangles[i]);
  const std::size_t dropped = mesh->triangles.size() - kept.size();
  mesh->triangles = std::move(kept);
  return dropped;
}

Box bounds(const Shape& shape) {
  Box box;
  if (shape.kind == Shape::Kind::Sphere) {
    box.add(shape.center - shape.radius);
    box.add(shape.center + shape.radius);
  } else {
    for (const vec3& p : shape.mesh.positions) box.add(p);
  }
  return box;
}

Box placed(const Box& box, const mat4& to_world) {
  Box out;
  if (!box.empty())
    for (int c = 0; c < 8; ++c) out.add(vec3(to_world * vec4(box.corner(c), 1.0f)));
  return out;
}

bool placed_finite(const Box& box, const mat4& to_world) {
  for (int c = 0; c < 8 && !box.empty(); ++c)
    if (!is_finite(vec3(to_world * vec4(box.corner(c), 1.0f)))) return false;
  return true;
}

bool placed_in_range(const Box& box, const mat4& to_world) {
  for (int c = 0; c < 8 && !box.empty(); ++c)
    if (!within_scene_range(vec3(to_world * vec4(box.corner(c), 1.0f)))) return false;
  return true;
}

namespace {
double max_abs(const dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }
}  // namespace

void check_scene_range(const Scene& scene) {
  const std::string file = scene.file.empty() ? "<built-in " + scene.name + ">" : scene.file.string();
  const std::string limit = " (the limit is 1e16 in each coordinate, so that every ray stays within Embree's 1.8e18)";
  const auto fail = [&](const std::string& what) { throw InputError(file + ": " + what + limit); };
  const CameraDesc& c = scene.camera;
  if (!within_scene_range(c.position)) fail("the camera position lies beyond the scene coordinate limit");
  if (!(c.aperture_radius <= kMaxSceneCoordinate) ||
      !within_scene_range(glm::abs(c.position) + vec3(c.aperture_radius)))
    fail("the camera aperture reaches beyond the scene coordinate limit");
  if (!(c.focus_distance <= kMaxSceneCoordinate)) fail("the camera focus distance exceeds the scene coordinate limit");
  for (const Shape& s : scene.shapes) {
    if (s.kind == Shape::Kind::Sphere) {
      if (!(s.radius >= kMinSphereRadius && s.radius <= kMaxSceneCoordinate))
        fail(s.description + ": the sphere's radius must lie in [1e-18, 1e16]");
      if (!within_scene_range(glm::abs(s.center) + vec3(s.radius)))
        fail(s.description + ": the sphere reaches beyond the scene coordinate limit");
      continue;
    }
    for (std::size_t v = 0; v < s.mesh.positions.size(); ++v)
      if (!within_scene_range(s.mesh.positions[v]))
        fail(s.description + ": vertex " + std::to_string(v) + " lies beyond the scene coordinate limit");
  }
  for (const DeltaLight& l : scene.delta_lights)
    if (l.kind != DeltaLight::Kind::Directional && !within_scene_range(l.position)) fail("a light's position lies beyond the scene coordinate limit");
  // Where rays start: the camera's lens, and points of the scene's surfaces
  // and lights (every ray direction is a unit vector).
  double reach = std::max(0.0, max_abs(dvec3(c.position)) + double(c.aperture_radius));
  const auto reach_box = [&reach](const Box& b) {
    if (!b.empty()) reach = std::max({reach, max_abs(dvec3(b.lo)), max_abs(dvec3(b.hi))});
  };
  for (const Shape& s : scene.shapes)
    if (!s.in_group) reach_box(bounds(s));
  for (const Instance& i : scene.instances) {
    Box box;
    for (const std::uint32_t id : scene.groups[i.group].shapes) box.add(bounds(scene.shapes[id]));
    if (!placed_in_range(box, i.to_world)) fail(i.description + ": the instance lies beyond the scene coordinate limit");
    reach_box(placed(box, i.to_world));
  }
  for (const DeltaLight& l : scene.delta_lights)
    if (l.kind != DeltaLight::Kind::Directional) reach = std::max(reach, max_abs(dvec3(l.position)));
  // Embree carries every ray into an instance's space (the inverse placement:
  // origin L^-1 (o - t), direction L^-1 d) and tests it there against the
  // same bound, so a placement that shrinks its group a great deal blows the
  // scene's rays up beyond it. Keep them within kMaxSceneCoordinate there
  // too: |L^-1|_inf (the largest absolute row sum) times the reach of an
  // origin (and times 1, a unit direction's).
  for (const Instance& i : scene.instances) {
    const glm::dmat3 inverse = glm::inverse(glm::dmat3(mat3(i.to_world)));
    double norm = 0.0;
    for (int r = 0; r < 3; ++r)
      norm = std::max(norm, std::abs(inverse[0][r]) + std::abs(inverse[1][r]) + std::abs(inverse[2][r]));
    const double local = norm * std::max(1.0, reach + max_abs(dvec3(i.to_world[3])));
    if (!(local <= double(kMaxSceneCoordinate))) {
      std::ostringstream m;
      m << i.description << ": the placement shrinks its group so much that a ray of the scene, carried into the "
        << "group's space as Embree does, would reach " << local << " (inverse placement's row sum " << norm
        << ", rays start up to " << reach << " from the origin); scale the group's content instead";
      fail(m.str());
    }
  }
}

bool invertible_placement(const mat4& to_world) {
  const float det = glm::determinant(mat3(to_world));
  if (!(std::abs(det) > 0.0f) || !std::isfinite(det) || !std::isfinite(1.0f / det)) return false;
  const mat4 inverse = glm::inverse(to_world);
  for (int c = 0; c < 4; ++c)
    if (!is_finite(vec3(to_world[c])) || !is_finite(vec3(inverse[c])) || !std::isfinite(inverse[c].w)) return false;
  return true;
}

double corner_angle(const dvec3& a, const dvec3& b, const dvec3& c) {
  const dvec3 e1 = b - a, e2 = c - a;
  return std::atan2(glm::length(glm::cross(e1, e2)), glm::dot(e1, e2));
}

float triangle_area(const TriangleMesh& mesh, std::uint32_t tri) {
  const glm::uvec3 t = mesh.triangles[tri];
  const dvec3 p0(mesh.positions[t.x]), p1(mesh.positions[t.y]), p2(mesh.positions[t.z]);
  return static_cast<float>(0.5 * glm::length(glm::cross(p1 - p0, p2 - p0)));
}

vec3 triangle_normal(const Shape& shape, std::uint32_t tri) {
  const glm::uvec3 t = shape.mesh.triangles[tri];
  const dvec3 p0(shape.mesh.positions[t.x]), p1(shape.mesh.positions[t.y]), p2(shape.mesh.positions[t.z]);
  const vec3 n(glm::normalize(glm::cross(p1 - p0, p2 - p0)));
  return shape.flip_normals ? -n : n;
}

Triangle make_triangle(const Shape& shape, std::uint32_t tri) {
  const glm::uvec3 t = shape.mesh.triangles[tri];
  return Triangle{shape.mesh.positions[t.x], shape.mesh.positions[t.y], shape.mesh.positions[t.z],
                  triangle_normal(shape, tri)};
}

// The point and its error bound (PBR 4th ed. 6.8.3: interpolation error of
// barycentric evaluation) by the generic function the wavefront's lanes run
// (core/simd/lanes-inl.h), at width 1.
SurfacePoint triangle_point(const Triangle& t, vec2 b) {
  using namespace width1;
  F3 p, error;
  generic::triangle_point(kScalar, F{b.x}, F{b.y}, lanes(t.p0), lanes(t.p1), lanes(t.p2), p, error);
  return SurfacePoint{scalars(p), scalars(error), t.n};
}

SurfacePoint triangle_point(const Shape& shape, std::uint32_t tri, vec2 b) {
  return triangle_point(make_triangle(shape, tri), b);
}

SurfacePoint sphere_point(const Shape& shape, const vec3& p_approx) {
  using namespace width1;
  F3 p, error, n;
  generic::sphere_point(kScalar, lanes(shape.center), F{shape.radius}, lane1::M{shape.flip_normals}, lanes(p_approx), p,
                        error, n);
  SurfacePoint sp;
  sp.p = scalars(p);
  sp.p_error = scalars(error);
  sp.n = scalars(n);
  return sp;
}

float sphere_crossing(const vec3& origin, const vec3& dir, float tnear, float tfar, const vec3& center, float radius) {
  constexpr float kNone = std::numeric_limits<float>::quiet_NaN();
  const dvec3 d(dir);
  const dvec3 f = dvec3(origin) - dvec3(center);  // exact unless the exponents lie ~29 binades apart
  const double r = radius;
  const double a = glm::dot(d, d);
  if (!(a > 0.0)) return kNone;
  // The quadratic a t^2 + 2 b t + c with b = f.d, c = |f|^2 - r^2. Its
  // discriminant b^2 - a c equals a (r^2 - l^2), l the distance from the
  // centre to the ray's line (g below): no difference of two large squares.
  const double b = glm::dot(f, d);
  const double c = glm::dot(f, f) - r * r;
  const dvec3 g = f - (b / a) * d;
  const double l = std::sqrt(glm::dot(g, g));
  const double disc = (r - l) * (r + l);
  if (!(disc > 0.0)) return kNone;  // a miss, or a touch (no crossing), or NaN
  const double root = std::sqrt(a * disc);
  const double q = -(b + std::copysign(root, b));  // |q| >= root > 0
  double t0 = q / a, t1 = c / q;
  if (t1 < t0) std::swap(t0, t1);
  for (const double t : {t0, t1}) {
    const auto tf = static_cast<float>(t);
    if (tf > tnear && tf < tfar) return tf;
  }
  return kNone;
}

// The generic shading_normal (core/simd/lanes-inl.h) at width 1.
vec3 shading_normal(const vec3& ng, const vec3& sum) {
  using namespace width1;
  return scalars(generic::shading_normal(kScalar, lanes(ng), lanes(sum)));
}

SurfacePoint sample_triangle(const Triangle& t, vec2 u) { return triangle_point(t, square_to_uniform_triangle(u)); }

SurfacePoint sample_triangle(const Shape& shape, std::uint32_t tri, vec2 u) {
  return sample_triangle(make_triangle(shape, tri), u);
}

SurfacePoint sample_sphere(const Shape& shape, vec2 u) {
  return sphere_point(shape, shape.center + shape.radius * square_to_uniform_sphere(u));
}

}  // namespace pathlab
