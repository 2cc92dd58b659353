// "textured-room": a closed Lambert room that emits Le everywhere and
// reflects with a textured albedo a(x), seen with the depth cap 1. The eye
// sees the first wall's emission plus one bounce of the walls' emission:
//   L(x) = Le (1 + a(x))
// exactly, whatever the strategy. a(x) is what the renderer reads: the
// texture filtered over the ray cone's footprint (core/ray_cone.h), which
// this model computes itself, in double precision, from the camera's pixel
// angle, the hit's distance and angle, and the surface's uv-to-world area
// ratio, and then looks up through the same Textures code (core/texture.h).
// So a footprint computed wrongly in CompiledScene::resolve (or a cone the
// tracers carry wrongly) makes the check fail, while the texture filter
// itself is taken as given (tests/test_textures.cpp checks lookups against
// closed forms).
//
// The room is a flat-shaded mesh with texture coordinates (a box), or a
// sphere, whose texture coordinates are pbrt's (phi, theta) about the z axis
// through its centre (docs/scene-format.md): here phi and theta from libm's
// double atan2, the uv area per world area 1 / (2 pi^2 r^2 sin theta) with
// sin theta at least 1e-4, as the renderer's. The sphere's seam (phi = 0,
// where u wraps from 1 to 0) is an edge; its poles lie on it.
#include "analytic-scenes/models.h"
#include "analytic-scenes/room.h"
#include "core/ray_cone.h"
#include "core/texture.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>

namespace pathlab::analytic {
namespace {

constexpr std::string_view kName = "textured-room";

class TexturedRoom final : public AnalyticModel {
 public:
  TexturedRoom(const Scene& scene, const Shape& room, const Material& m)
      : room_(room), Le_(m.emission), ref_(m.texture_of(MaterialParam::Albedo)->texture),
        textures_(std::make_unique<Textures>(scene.textures, scene.render.texture_cache_mb)),
        spread_(scene.render.texture_filter == TextureFilter::Cone
                    ? pixel_spread_angle(scene.camera.fov_y_degrees, scene.film.height)
                    : 0.0f) {}

  std::string_view name() const override { return kName; }
  // The room's edges, where the texture coordinates and the footprint jump;
  // the bilinear texture is continuous within a wall. A sphere's seam.
  void edges(EdgeList& out) const override {
    if (room_.kind != Shape::Kind::Sphere) return out.mesh_edges(room_);
    const dvec3 c(room_.center);
    const double r = room_.radius;
    out.point_curve([&](double theta) { return c + r * dvec3(std::sin(theta), 0.0, std::cos(theta)); }, 0.0, std::numbers::pi, 64);
  }
  std::string describe() const override {
    std::ostringstream s;
    if (room_.kind == Shape::Kind::Sphere)
      s << "sphere of radius " << room_.radius;
    else
      s << "room of " << room_.mesh.triangles.size() << " triangles";
    s << " emitting Le = (" << Le_.x << ", " << Le_.y << ", " << Le_.z << "), albedo from a texture, cone spread "
      << spread_ << " rad, depth cap 1: L = Le (1 + a(x))";
    return s.str();
  }

  Spectrum radiance(const Ray& ray) const override {
    const dvec3 o(ray.origin), d = glm::normalize(dvec3(ray.dir));
    double best = kInfinity;
    vec2 uv(0.0f);
    double uv_per_area = 0.0, cos_theta = 1.0;
    if (room_.kind == Shape::Kind::Sphere) {
      const std::optional<double> t = hit_sphere(room_.center, room_.radius, ray);
      if (!t) return Spectrum(0.0f);  // cannot happen inside a closed room
      best = *t;
      const double r = room_.radius;
      const dvec3 n = (o + best * d - dvec3(room_.center)) / r;
      double phi = std::atan2(n.y, n.x);
      if (phi < 0.0) phi += 2.0 * std::numbers::pi;
      const double sin_theta = std::hypot(n.x, n.y);
      uv = vec2(static_cast<float>(phi / (2.0 * std::numbers::pi)), static_cast<float>(1.0 - std::atan2(sin_theta, n.z) / std::numbers::pi));
      uv_per_area = 1.0 / (2.0 * std::numbers::pi * std::numbers::pi * r * r * std::max(sin_theta, 1e-4));
      cos_theta = std::abs(glm::dot(d, n));
    }
    const TriangleMesh& m = room_.mesh;
    for (const glm::uvec3& t : m.triangles) {
      const dvec3 p0(m.positions[t.x]), p1(m.positions[t.y]), p2(m.positions[t.z]);
      // Möller-Trumbore, keeping the barycentrics.
      const dvec3 e1 = p1 - p0, e2 = p2 - p0, q = glm::cross(d, e2);
      const double det = glm::dot(e1, q);
      if (det == 0.0) continue;
      const dvec3 s = o - p0;
      const double b1 = glm::dot(s, q) / det;
      const dvec3 r = glm::cross(s, e1);
      const double b2 = glm::dot(d, r) / det, dist = glm::dot(e2, r) / det;
      if (b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 || dist <= 0.0 || dist >= best) continue;
      best = dist;
      const glm::dvec2 w0(m.uvs[t.x]), w1(m.uvs[t.y]), w2(m.uvs[t.z]);
      uv = vec2((1.0 - b1 - b2) * w0 + b1 * w1 + b2 * w2);
      const glm::dvec2 a = w1 - w0, b = w2 - w0;
      const dvec3 n = glm::cross(e1, e2);
      uv_per_area = std::abs(a.x * b.y - a.y * b.x) / glm::length(n);
      cos_theta = std::abs(glm::dot(d, n)) / glm::length(n);
    }
    if (!(best < kInfinity)) return Spectrum(0.0f);  // cannot happen inside a closed room
    const double width = best * double(spread_) / cos_theta * std::sqrt(uv_per_area);
    const Spectrum a = glm::clamp(textures_->color(ref_, {uv, static_cast<float>(width)}), Spectrum(0.0f), Spectrum(1.0f));
    return Le_ * (1.0f + a);
  }

 private:
  const Shape& room_;
  Spectrum Le_;
  TextureRef ref_;
  std::unique_ptr<Textures> textures_;
  float spread_;
};

}  // namespace

std::unique_ptr<AnalyticModel> make_textured_room(const Scene& scene) {
  if (scene.shapes.size() != 1)
    refuse(scene, kName, "the scene must hold exactly one shape: the room, a closed triangle mesh (a box) or a sphere");
  const Shape& room = scene.shapes[0];
  const Material& m = scene.materials[room.material];
  if (!is_closed(room)) refuse(scene, kName, "the room is not closed");
  if (m.type != MaterialType::Diffuse || m.texture_of(MaterialParam::Albedo) == nullptr)
    refuse(scene, kName, "the room's material must be diffuse with a textured albedo");
  if (m.textured.size() != 1 || m.normal_map || m.one_sided)
    refuse(scene, kName, "the room's material may texture its albedo only (no other texture, no normal map, two-sided)");
  if (!emits_inwards(room, m) || is_black(m.emission)) refuse(scene, kName, "the room must emit towards its inside");
  if (room.kind == Shape::Kind::Triangles && !room.mesh.has_uvs()) refuse(scene, kName, "the room needs texture coordinates");
  if (room.mesh.has_normals()) refuse(scene, kName, "the room must be flat-shaded");
  if (scene.render.max_depth != 1) refuse(scene, kName, "the model holds for max_depth 1 only");
  if (!scene.delta_lights.empty() || scene.environment) refuse(scene, kName, "the room's walls must be the only light");
  if (!contains(room, scene.camera.position)) refuse(scene, kName, "the camera must be inside the room");
  return std::make_unique<TexturedRoom>(scene, room, m);
}

}  // namespace pathlab::analytic
