// Model "plane-under-sun": one sun disk (a directional light with an
// angular diameter 2 alpha: radiance E / (pi sin^2 alpha) in the cone of
// half-angle alpha about -direction) over one plane (a planar mesh) of a
// two-sided diffuse material of albedo a, the camera on the sunny side.
// The disk's axis makes angle theta with the plane's normal and lies wholly
// above the plane (theta + alpha <= 90 degrees); then the cosine-weighted
// solid angle of the disk is exactly pi sin^2 alpha cos theta (the integral
// of the normal's cosine over a spherical cap is the cap's projected area
// along its axis times cos theta), so every point of the plane receives
// E cos theta and shows
//   L = a E cos theta / pi          (0 with a depth cap of 0 bounces).
// A camera ray that misses the plane carries the disk's radiance if it
// points into the cone, else 0. Nothing else may light the scene.
#include "analytic-scenes/models.h"
#include "analytic-scenes/room.h"

#include <array>
#include <cmath>
#include <sstream>
#include <vector>

namespace pathlab::analytic {
namespace {

class PlaneUnderSun final : public AnalyticModel {
 public:
  PlaneUnderSun(const Shape& plane, const DeltaLight& sun, Spectrum on_plane, std::string description)
      : to_sun_(-glm::normalize(dvec3(sun.direction))),
        cos_alpha_(std::cos(double(sun.angular_radius))),
        sun_radiance_(dvec3(sun.intensity) / (M_PI * std::pow(std::sin(double(sun.angular_radius)), 2))),
        on_plane_(on_plane),
        description_(std::move(description)),
        plane_(plane) {
    for (const glm::uvec3& t : plane.mesh.triangles)
      triangles_.push_back({dvec3(plane.mesh.positions[t.x]), dvec3(plane.mesh.positions[t.y]), dvec3(plane.mesh.positions[t.z])});
  }
  std::string_view name() const override { return "plane-under-sun"; }
  Spectrum radiance(const Ray& ray) const override {
    const dvec3 o(ray.origin), d(ray.dir);
    for (const auto& t : triangles_)
      if (hit_triangle(o, d, t[0], t[1], t[2])) return on_plane_;
    return glm::dot(glm::normalize(d), to_sun_) >= cos_alpha_ ? Spectrum(sun_radiance_) : Spectrum(0.0f);
  }
  void edges(EdgeList& out) const override {
    out.mesh_edges(plane_);
    out.cone(to_sun_, cos_alpha_);
  }
  std::string describe() const override { return description_; }

 private:
  std::vector<std::array<dvec3, 3>> triangles_;
  dvec3 to_sun_;
  double cos_alpha_;
  dvec3 sun_radiance_;
  Spectrum on_plane_;
  std::string description_;
  Shape plane_;  // for its edges
};

}  // namespace

std::unique_ptr<AnalyticModel> make_plane_under_sun(const Scene& scene) {
  constexpr std::string_view kName = "plane-under-sun";
  if (scene.delta_lights.size() != 1 || !scene.delta_lights[0].is_sun_disk())
    refuse(scene, kName, "needs exactly one light, a directional light with an angular_diameter");
  if (scene.environment || scene.environment_map) refuse(scene, kName, "an environment would light the plane too; remove it");
  if (scene.shapes.size() != 1 || scene.shapes[0].kind != Shape::Kind::Triangles)
    refuse(scene, kName, "needs exactly one shape, a planar mesh");
  const DeltaLight& sun = scene.delta_lights[0];
  const Shape& plane = scene.shapes[0];
  const Material& m = scene.materials[plane.material];
  if (m.type != MaterialType::Diffuse || m.one_sided || m.emits())
    refuse(scene, kName, "the plane must be of a two-sided, non-emitting diffuse material");
  const TriangleMesh& mesh = plane.mesh;
  const dvec3 p0(mesh.positions[mesh.triangles[0].x]), p1(mesh.positions[mesh.triangles[0].y]),
      p2(mesh.positions[mesh.triangles[0].z]);
  dvec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
  for (const glm::uvec3& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      if (std::abs(glm::dot(n, dvec3(mesh.positions[t[k]]) - p0)) > 1e-5 * (1.0 + glm::length(p0)))
        refuse(scene, kName, "the mesh must be planar");
  const dvec3 to_sun = -glm::normalize(dvec3(sun.direction));
  if (glm::dot(n, to_sun) < 0.0) n = -n;  // the sunny side
  if (!(glm::dot(n, dvec3(scene.camera.position) - p0) > 0.0)) refuse(scene, kName, "the camera must be on the sunny side");
  const double cos_theta = glm::dot(n, to_sun);
  const double theta = std::acos(std::min(1.0, cos_theta));
  if (theta + double(sun.angular_radius) > 0.5 * M_PI + 1e-9)
    refuse(scene, kName, "the whole sun disk must lie above the plane (its tilt plus half its diameter at most 90 degrees)");
  const Spectrum on = scene.render.max_depth == 0 ? Spectrum(0.0f)
                                                  : Spectrum(dvec3(m.albedo) * dvec3(sun.intensity) * cos_theta / M_PI);
  std::ostringstream d;
  d << "sun disk of diameter " << 2.0 * sun.angular_radius * 180.0 / M_PI << " degrees, irradiance (" << sun.intensity.x
    << ", " << sun.intensity.y << ", " << sun.intensity.z << ") at " << theta * 180.0 / M_PI << " degrees from the normal of plane '"
    << m.name << "' (" << on.x << ", " << on.y << ", " << on.z << "), depth cap " << scene.render.max_depth;
  return std::make_unique<PlaneUnderSun>(plane, sun, on, d.str());
}

}  // namespace pathlab::analytic
