// Model "furnace": the camera inside one closed room (a sphere or a
// watertight mesh) made of a single Lambert material of albedo rho that emits
// Le towards the inside. Radiance is the same along every ray:
//   L = Le (1 + rho + ... + rho^D) = Le (1 - rho^(D+1)) / (1 - rho)
// with D the depth cap (max_depth: the number of bounces; D = 0 sees only
// emission), and Le / (1 - rho) without a cap (max_depth -1, Russian
// roulette), which needs rho < 1.
#include "analytic-scenes/models.h"
#include "analytic-scenes/room.h"

#include <sstream>

namespace pathlab::analytic {

Spectrum furnace_radiance(const Spectrum& Le, const Spectrum& rho, int max_depth) {
  Spectrum L;
  for (int c = 0; c < 3; ++c) {
    const double r = rho[c];
    L[c] = static_cast<float>(max_depth < 0 ? Le[c] / (1.0 - r)
                                            : r == 1.0 ? Le[c] * (max_depth + 1.0)
                                                       : Le[c] * (1.0 - std::pow(r, max_depth + 1)) / (1.0 - r));
  }
  return L;
}

namespace {

class Furnace final : public AnalyticModel {
 public:
  Furnace(Spectrum L, std::string description) : L_(L), description_(std::move(description)) {}
  std::string_view name() const override { return "furnace"; }
  Spectrum radiance(const Ray&) const override { return L_; }
  void edges(EdgeList&) const override {}  // the same radiance everywhere
  std::string describe() const override { return description_; }

 private:
  Spectrum L_;
  std::string description_;
};

}  // namespace

std::unique_ptr<AnalyticModel> make_furnace(const Scene& scene) {
  constexpr std::string_view kName = "furnace";
  if (scene.shapes.size() != 1) refuse(scene, kName, "needs exactly one shape, the room; found " + std::to_string(scene.shapes.size()));
  const Shape& room = scene.shapes[0];
  const Material& m = scene.materials[room.material];
  if (m.type != MaterialType::Diffuse) refuse(scene, kName, "the room must be a diffuse (Lambert) material");
  if (!m.emits()) refuse(scene, kName, "the room must emit (give its material an emission)");
  if (!is_closed(room)) refuse(scene, kName, "the room must be closed: a sphere or a watertight mesh (" + room.description + " has open edges)");
  if (!contains(room, scene.camera.position)) refuse(scene, kName, "the camera must be inside the room");
  if (!emits_inwards(room, m))
    refuse(scene, kName, "the room's emission faces outwards: set \"flip_normals\": true or \"two_sided\": true");
  if (!scene.delta_lights.empty()) refuse(scene, kName, "delta lights (point, spot, directional) break the uniform radiance; remove them");
  const int D = scene.render.max_depth;
  // Seen from inside, a one-sided room whose front faces out reflects nothing.
  const Spectrum rho = reflectance_inside(room, m);
  if (D < 0 && max_component(rho) >= 1.0f)
    refuse(scene, kName, "without a depth cap the albedo must be below 1 (the series diverges)");
  std::ostringstream d;
  d << "room '" << m.name << "' Le (" << m.emission.x << ", " << m.emission.y << ", " << m.emission.z << ") albedo ("
    << m.albedo.x << ", " << m.albedo.y << ", " << m.albedo.z << ")"
    << (m.one_sided ? (is_black(rho) ? ", one-sided and seen from its back (reflects nothing)" : ", one-sided") : "")
    << ", depth cap " << D;
  return std::make_unique<Furnace>(furnace_radiance(m.emission, rho, D), d.str());
}

}  // namespace pathlab::analytic
