// Model "sphere-in-uniform-light": one sphere, Lambert (albedo a) or mirror
// (reflectance R), surrounded by light of uniform radiance L_s, which is
// either
//   - a uniform environment, or an environment image whose texels are all
//     equal (then the sphere must be the only shape), or
//   - a closed room around the camera and the sphere whose walls emit Le
//     towards the inside and reflect nothing (material "emissive"): L_s = Le,
//   - or such a room with Lambert walls of albedo rho emitting Le, when the
//     sphere is a perfect mirror (R = 1) and there is no depth cap: a mirror
//     of reflectance 1 conserves radiance, so the room is a furnace,
//     L_s = Le / (1 - rho).
// Being convex, the sphere sees only its surroundings, so a camera ray
// that hits it carries a L_s (Lambert) or R L_s (mirror), given a depth cap
// of at least one bounce (0 otherwise); any other ray carries L_s.
#include "analytic-scenes/models.h"
#include "analytic-scenes/room.h"
#include "core/environment_map.h"

#include <sstream>

namespace pathlab::analytic {
namespace {

class SphereInUniformLight final : public AnalyticModel {
 public:
  SphereInUniformLight(const Shape& sphere, Spectrum on, Spectrum off, std::string description)
      : center_(sphere.center), radius_(sphere.radius), on_(on), off_(off), description_(std::move(description)) {}
  std::string_view name() const override { return "sphere-in-uniform-light"; }
  Spectrum radiance(const Ray& ray) const override { return hit_sphere(center_, radius_, ray) ? on_ : off_; }
  void edges(EdgeList& out) const override { out.sphere_silhouette(dvec3(center_), radius_); }
  std::string describe() const override { return description_; }

 private:
  vec3 center_;
  float radius_;
  Spectrum on_, off_;
  std::string description_;
};

std::string fmt(const Spectrum& c) {
  std::ostringstream s;
  s << "(" << c.x << ", " << c.y << ", " << c.z << ")";
  return s.str();
}

}  // namespace

std::unique_ptr<AnalyticModel> make_sphere_in_uniform_light(const Scene& scene) {
  constexpr std::string_view kName = "sphere-in-uniform-light";
  const Shape* sphere = nullptr;
  const Shape* room = nullptr;
  for (const Shape& s : scene.shapes) {
    const bool is_room = s.kind != Shape::Kind::Sphere || scene.materials[s.material].emits();
    if (is_room) {
      if (room) refuse(scene, kName, "needs one sphere and at most one room; found two room shapes");
      room = &s;
    } else {
      if (sphere) refuse(scene, kName, "needs exactly one non-emitting sphere; found two");
      sphere = &s;
    }
  }
  if (!sphere) refuse(scene, kName, "needs a non-emitting sphere");
  const Material& sm = scene.materials[sphere->material];
  if (sm.type != MaterialType::Diffuse && sm.type != MaterialType::Mirror)
    refuse(scene, kName, "the sphere must be diffuse or mirror");
  if (!scene.delta_lights.empty()) refuse(scene, kName, "delta lights (point, spot, directional) break the uniform surroundings; remove them");
  const int D = scene.render.max_depth;

  Spectrum surround;
  std::string what;
  if (!room) {
    // An environment image whose texels are all equal is uniform too (its
    // lookup and importance sampling differ from the uniform light's, its
    // radiance does not).
    std::optional<Spectrum> uniform = scene.environment;
    if (!uniform && scene.environment_map) uniform = scene.environment_map->constant();
    if (!uniform)
      refuse(scene, kName,
             scene.environment_map ? "the environment image is not constant: its radiance is not uniform"
                                   : "needs a uniform environment or a closed emitting room around the sphere");
    surround = *uniform;
    what = (scene.environment ? "environment " : "constant environment image ") + fmt(surround);
  } else {
    if ((scene.environment && !is_black(*scene.environment)) ||
        (scene.environment_map && !scene.environment_map->is_black()))
      refuse(scene, kName, "give either an environment or a room, not both");
    const Material& rm = scene.materials[room->material];
    if (!rm.emits()) refuse(scene, kName, "the room must emit");
    if (!is_closed(*room)) refuse(scene, kName, "the room must be closed: a sphere or a watertight mesh");
    if (!contains(*room, scene.camera.position)) refuse(scene, kName, "the camera must be inside the room");
    if (!contains(*room, sphere->center)) refuse(scene, kName, "the sphere must be inside the room");
    if (!emits_inwards(*room, rm))
      refuse(scene, kName, "the room's emission faces outwards: set \"flip_normals\": true or \"two_sided\": true");
    if (!is_black(reflectance_inside(*room, rm))) {
      if (!(sm.type == MaterialType::Mirror && sm.albedo == Spectrum(1.0f) && D < 0 &&
            rm.type == MaterialType::Diffuse && max_component(rm.albedo) < 1.0f))
        refuse(scene, kName,
               "a room whose walls reflect has uniform radiance only around a perfect mirror (reflectance 1) "
               "without a depth cap (max_depth -1) and wall albedo below 1; use an \"emissive\" room otherwise");
      surround = furnace_radiance(rm.emission, rm.albedo, -1);
    } else {
      surround = rm.emission;
    }
    what = "room '" + rm.name + "' radiance " + fmt(surround);
  }
  // The camera and the light are outside the sphere: a one-sided sphere
  // whose front faces in reflects nothing.
  const Spectrum albedo = sm.one_sided && sphere->flip_normals ? Spectrum(0.0f) : sm.albedo;
  const Spectrum on = D == 0 ? Spectrum(0.0f) : albedo * surround;
  const std::string description = std::string(material_type_name(sm.type)) + " sphere '" + sm.name + "' " + fmt(sm.albedo) +
                                  " in " + what + ", depth cap " + std::to_string(D) + ": sphere " + fmt(on);
  return std::make_unique<SphereInUniformLight>(*sphere, on, surround, description);
}

}  // namespace pathlab::analytic
