// Model "environment-map": an environment image (core/environment_map.h)
// seen directly, and at most one shape:
//   - a perfect mirror sphere (reflectance R): a camera ray that hits it
//     carries R times the map's radiance in the reflected direction (0 with a
//     depth cap of 0 bounces): the sphere is convex, so the reflected ray
//     escapes;
//   - a planar diffuse mesh (albedo a) facing the map's up (+y turned by the
//     map's transform), the camera above it: a point on it sees exactly the
//     upper hemisphere of the map, whose rows are bands of polar angle
//     [theta0, theta1) about that normal, so its irradiance is exactly
//       E = sum over the upper rows and all columns of
//           L(texel) (2 pi / width) (sin^2 theta1 - sin^2 theta0) / 2
//     and it shows a E / pi (D >= 1). Light sampling, BSDF sampling and
//     their MIS weights all meet the map there.
// A ray that misses the shape carries the map's radiance in its direction.
// Sun disks (directional lights with an angular diameter) may join the map:
// they add their radiance E / (pi sin^2 alpha) inside their cones, and to
// the plane a E cos theta / pi each (exact when the whole disk is above the
// plane, which the model requires).
//
// The map is piecewise constant, so the expected pixel values have edges
// wherever a pixel straddles a texel boundary. Seen directly, those edges
// are listed (edges()) and expected_image() refines along them; mirrored in
// the sphere they are not, and there it refines its midpoint grid up to
// 128^2 per pixel and reports the last difference as the quadrature error,
// which check() adds to each pixel's tolerance (measured for the committed
// scenes in docs/analytic-scenes.md: far below the noise).
#include "analytic-scenes/models.h"
#include "analytic-scenes/room.h"
#include "core/environment_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <vector>

namespace pathlab::analytic {
namespace {

// Irradiance on a surface whose normal is the map's up, from the upper
// hemisphere (rows whose polar angle is below pi/2), exactly.
dvec3 upper_hemisphere_irradiance(const EnvironmentMap& map) {
  dvec3 E(0.0);
  const int w = map.width(), h = map.height();
  for (int y = 0; y < h / 2; ++y) {
    const double s0 = std::sin(M_PI * y / h), s1 = std::sin(M_PI * (y + 1) / h);
    const double band = (2.0 * M_PI / w) * 0.5 * (s1 * s1 - s0 * s0);
    for (int x = 0; x < w; ++x) E += band * dvec3(map.texels().at(x, y));
  }
  return E;
}

struct Sun {
  dvec3 to_sun;
  double cos_alpha;
  dvec3 radiance;
};

class EnvironmentMapModel final : public AnalyticModel {
 public:
  EnvironmentMapModel(std::shared_ptr<const EnvironmentMap> map, std::vector<Sun> suns, const Shape* shape,
                      Spectrum surface, std::string description)
      : map_(std::move(map)), suns_(std::move(suns)), description_(std::move(description)), surface_(surface) {
    if (shape && shape->kind == Shape::Kind::Sphere) {
      has_sphere_ = true;
      center_ = shape->center;
      radius_ = shape->radius;
    } else if (shape) {
      plane_shape_ = *shape;
      for (const glm::uvec3& t : shape->mesh.triangles)
        plane_.push_back({dvec3(shape->mesh.positions[t.x]), dvec3(shape->mesh.positions[t.y]),
                          dvec3(shape->mesh.positions[t.z])});
    }
  }
  std::string_view name() const override { return "environment-map"; }
  Spectrum radiance(const Ray& ray) const override {
    if (!plane_.empty()) {
      const dvec3 o(ray.origin), d(ray.dir);
      for (const auto& t : plane_)
        if (hit_triangle(o, d, t[0], t[1], t[2])) return surface_;
      return sky(ray.dir);
    }
    if (has_sphere_) {
      if (const std::optional<double> t = hit_sphere(center_, radius_, ray)) {
        // In double: the reflected direction of the exact hit point.
        const dvec3 o(ray.origin), d(ray.dir), c(center_);
        const dvec3 n = glm::normalize(o + *t * d - c);
        const dvec3 r = d - 2.0 * glm::dot(d, n) * n;
        return surface_ * sky(vec3(glm::normalize(r)));
      }
    }
    return sky(ray.dir);
  }
  std::string describe() const override { return description_; }
  // The plane's outline or the sphere's silhouette; the suns' disks and the
  // map's texel edges where the sky is seen directly. Their reflections in
  // the mirror sphere are curves this model does not list.
  void edges(EdgeList& out) const override {
    if (!plane_.empty()) out.mesh_edges(plane_shape_);
    if (has_sphere_) {
      out.sphere_silhouette(dvec3(center_), radius_);
      if (!map_->constant() || !suns_.empty()) out.note_unlisted("the map's texel edges and sun disks mirrored in the sphere");
    }
    for (const Sun& sun : suns_) out.cone(sun.to_sun, sun.cos_alpha);
    if (map_->constant()) return;
    const glm::dmat3 to_world(map_->to_world());
    const int w = map_->width(), h = map_->height();
    const auto dir = [&](double u, double v) {
      return to_world * dvec3(EnvironmentMap::uv_to_direction(vec2(static_cast<float>(u), static_cast<float>(v))));
    };
    // Columns' edges: half great circles from pole to pole, in pieces under
    // 180 degrees; rows' edges: circles of constant polar angle.
    for (int j = 0; j < w; ++j)
      out.direction_curve([&](double v) { return dir(static_cast<double>(j) / w, v); }, 0.0, 1.0, 2 * h);
    for (int i = 1; i < h; ++i)
      out.direction_curve([&](double u) { return dir(u, static_cast<double>(i) / h); }, 0.0, 1.0, std::max(1024, 4 * w));
  }

 private:
  Spectrum sky(const vec3& dir) const {
    dvec3 L(map_->radiance(dir));
    for (const Sun& sun : suns_)
      if (glm::dot(glm::normalize(dvec3(dir)), sun.to_sun) >= sun.cos_alpha) L += sun.radiance;
    return Spectrum(L);
  }

  std::shared_ptr<const EnvironmentMap> map_;
  std::vector<Sun> suns_;
  std::string description_;
  Spectrum surface_{0.0f};  // the sphere's reflectance, or the plane's radiance
  std::vector<std::array<dvec3, 3>> plane_;  // the plane's triangles
  Shape plane_shape_;                        // and the plane itself, for its edges
  bool has_sphere_ = false;
  vec3 center_{0.0f};
  float radius_ = 0.0f;
};

}  // namespace

std::unique_ptr<AnalyticModel> make_environment_map(const Scene& scene) {
  constexpr std::string_view kName = "environment-map";
  if (!scene.environment_map) refuse(scene, kName, "needs an environment image (a light with \"file\")");
  std::vector<Sun> suns;
  for (const DeltaLight& dl : scene.delta_lights) {
    if (!dl.is_sun_disk())
      refuse(scene, kName, "delta lights (point, spot, directional without an angular_diameter) cannot be seen; remove them");
    const double sin_alpha = std::sin(double(dl.angular_radius));
    suns.push_back({-glm::normalize(dvec3(dl.direction)), std::cos(double(dl.angular_radius)),
                    dvec3(dl.intensity) / (M_PI * sin_alpha * sin_alpha)});
  }
  if (scene.shapes.size() > 1)
    refuse(scene, kName, "needs at most one shape, a mirror sphere or a diffuse plane; found " + std::to_string(scene.shapes.size()));
  const Shape* shape = nullptr;
  Spectrum surface(0.0f);
  const EnvironmentMap& map = *scene.environment_map;
  std::ostringstream d;
  d << "environment " << map.source() << " (" << map.width() << " x " << map.height() << ")";
  if (!scene.shapes.empty()) {
    shape = &scene.shapes[0];
    const Material& m = scene.materials[shape->material];
    if (m.emits()) refuse(scene, kName, "the shape must not emit");
    const bool black = scene.render.max_depth == 0;
    if (shape->kind == Shape::Kind::Sphere) {
      if (m.type != MaterialType::Mirror) refuse(scene, kName, "a sphere must be a mirror");
      // The camera is outside: a one-sided sphere facing in reflects nothing.
      const bool faces_away = m.one_sided && shape->flip_normals;
      surface = black || faces_away ? Spectrum(0.0f) : m.albedo;
      d << ", mirror sphere '" << m.name << "' reflectance (" << surface.x << ", " << surface.y << ", " << surface.z << ")";
    } else {
      if (m.type != MaterialType::Diffuse || m.one_sided)
        refuse(scene, kName, "a mesh must be a plane of a two-sided diffuse material");
      const dvec3 up = glm::normalize(dvec3(map.to_world() * vec3(0.0f, 1.0f, 0.0f)));
      const TriangleMesh& mesh = shape->mesh;
      const double height = glm::dot(up, dvec3(mesh.positions[mesh.triangles[0].x]));
      for (const glm::uvec3& t : mesh.triangles) {
        const dvec3 p0(mesh.positions[t.x]), p1(mesh.positions[t.y]), p2(mesh.positions[t.z]);
        const dvec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
        if (std::abs(std::abs(glm::dot(n, up)) - 1.0) > 1e-6)
          refuse(scene, kName, "the plane must face the environment's up (+y, turned by its transform)");
        for (const dvec3& p : {p0, p1, p2})
          if (std::abs(glm::dot(up, p) - height) > 1e-5 * (1.0 + std::abs(height)))
            refuse(scene, kName, "the mesh must be planar");
      }
      if (!(glm::dot(up, dvec3(scene.camera.position)) > height)) refuse(scene, kName, "the camera must be above the plane");
      dvec3 E = upper_hemisphere_irradiance(map);
      for (std::size_t i = 0; i < suns.size(); ++i) {
        const DeltaLight& dl = scene.delta_lights[i];
        const double cos_theta = glm::dot(suns[i].to_sun, up);
        if (std::acos(std::clamp(cos_theta, -1.0, 1.0)) + double(dl.angular_radius) > 0.5 * M_PI + 1e-9)
          refuse(scene, kName, "a sun disk must lie wholly above the plane");
        E += dvec3(dl.intensity) * cos_theta;
      }
      surface = black ? Spectrum(0.0f) : Spectrum(dvec3(m.albedo) * E / M_PI);
      d << ", diffuse plane '" << m.name << "' irradiance (" << E.x << ", " << E.y << ", " << E.z << ")";
    }
  }
  d << ", depth cap " << scene.render.max_depth;
  if (!suns.empty()) d << ", " << suns.size() << " sun disk(s)";
  return std::make_unique<EnvironmentMapModel>(scene.environment_map, std::move(suns), shape, surface, d.str());
}

}  // namespace pathlab::analytic
