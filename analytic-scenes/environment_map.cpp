// Model "environment-map": an environment image (core/environment_map.h)
// seen directly, and optionally in one perfect mirror sphere (reflectance R,
// the only shape). A camera ray that misses the sphere carries the map's
// radiance in its direction; one that hits it carries R times the map's
// radiance in the reflected direction (0 with a depth cap of 0 bounces):
// the sphere is convex, so the reflected ray escapes.
//
// The map is piecewise constant, so the expected pixel values have edges
// wherever a pixel straddles a texel boundary; expected_image() refines its
// midpoint grid to 128^2 per pixel and reports the last difference as the
// quadrature error, which check() adds to each pixel's tolerance (measured
// for the committed scenes in docs/analytic-scenes.md: far below the noise).
#include "analytic-scenes/models.h"
#include "analytic-scenes/room.h"
#include "core/environment_map.h"

#include <sstream>

namespace pathlab::analytic {
namespace {

class EnvironmentMapModel final : public AnalyticModel {
 public:
  EnvironmentMapModel(std::shared_ptr<const EnvironmentMap> map, const Shape* sphere, Spectrum reflectance,
                      std::string description)
      : map_(std::move(map)), description_(std::move(description)), reflectance_(reflectance) {
    if (sphere) {
      has_sphere_ = true;
      center_ = sphere->center;
      radius_ = sphere->radius;
    }
  }
  std::string_view name() const override { return "environment-map"; }
  Spectrum radiance(const Ray& ray) const override {
    if (has_sphere_) {
      if (const std::optional<double> t = hit_sphere(center_, radius_, ray)) {
        // In double: the reflected direction of the exact hit point.
        const dvec3 o(ray.origin), d(ray.dir), c(center_);
        const dvec3 n = glm::normalize(o + *t * d - c);
        const dvec3 r = d - 2.0 * glm::dot(d, n) * n;
        return reflectance_ * map_->radiance(vec3(glm::normalize(r)));
      }
    }
    return map_->radiance(ray.dir);
  }
  std::string describe() const override { return description_; }

 private:
  std::shared_ptr<const EnvironmentMap> map_;
  std::string description_;
  Spectrum reflectance_{0.0f};
  bool has_sphere_ = false;
  vec3 center_{0.0f};
  float radius_ = 0.0f;
};

}  // namespace

std::unique_ptr<AnalyticModel> make_environment_map(const Scene& scene) {
  constexpr std::string_view kName = "environment-map";
  if (!scene.environment_map) refuse(scene, kName, "needs an environment image (a light with \"file\")");
  if (!scene.delta_lights.empty()) refuse(scene, kName, "delta lights (point, spot, directional) would light the sphere; remove them");
  if (scene.shapes.size() > 1) refuse(scene, kName, "needs at most one shape, a mirror sphere; found " + std::to_string(scene.shapes.size()));
  const Shape* sphere = nullptr;
  Spectrum R(0.0f);
  std::ostringstream d;
  d << "environment " << scene.environment_map->source() << " (" << scene.environment_map->width() << " x "
    << scene.environment_map->height() << ")";
  if (!scene.shapes.empty()) {
    sphere = &scene.shapes[0];
    const Material& m = scene.materials[sphere->material];
    if (sphere->kind != Shape::Kind::Sphere || m.type != MaterialType::Mirror)
      refuse(scene, kName, "the shape must be a mirror sphere");
    if (m.emits()) refuse(scene, kName, "the mirror sphere must not emit");
    // The camera is outside: a one-sided sphere facing in reflects nothing.
    const bool faces_away = m.one_sided && sphere->flip_normals;
    R = scene.render.max_depth == 0 || faces_away ? Spectrum(0.0f) : m.albedo;
    d << ", mirror sphere '" << m.name << "' reflectance (" << R.x << ", " << R.y << ", " << R.z << ")";
  }
  d << ", depth cap " << scene.render.max_depth;
  return std::make_unique<EnvironmentMapModel>(scene.environment_map, sphere, R, d.str());
}

}  // namespace pathlab::analytic
