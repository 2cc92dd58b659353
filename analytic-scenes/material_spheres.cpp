// Two models of one sphere, the only shape, under a uniform environment of
// radiance L (no point lights). Being convex, the sphere never sees itself.
//
// "rough-sphere-in-environment": an isotropic Disney sphere (anisotropic 0;
// e.g. a rough conductor). A camera ray hitting it at view cosine mu
// carries L * albedo(mu), the directional albedo int f cos d(omega_i), given
// a depth cap of at least one bounce; the albedo comes from deterministic
// quadrature of the BRDF (core/bsdf/quadrature.h), tabulated over mu.
//
// "glass-sphere-in-environment": a smooth dielectric sphere (ior eta,
// reflectance tint R, transmittance tint T). Inside a sphere every internal
// hit has the refracted angle, whose Fresnel reflectance equals the
// outside one, F = F(mu, eta), and never totally reflects. So a ray hitting
// at view cosine mu carries
//   L [R F + T^2 (1 - F)^2 sum_{j=0}^{D-2} (R F)^j]
// with D the depth cap (the sum to infinity without one: for white tints
// L, the sphere disappears).
#include "analytic-scenes/models.h"
#include "analytic-scenes/room.h"
#include "core/bsdf/disney.h"
#include "core/bsdf/fresnel.h"
#include "core/bsdf/quadrature.h"

#include <array>
#include <map>
#include <mutex>
#include <sstream>
#include <vector>

namespace pathlab::analytic {
namespace {

std::string fmt(const Spectrum& c) {
  std::ostringstream s;
  s << "(" << c.x << ", " << c.y << ", " << c.z << ")";
  return s.str();
}

// The one sphere of the scene and its material; refuses anything else.
const Shape& lone_sphere(const Scene& scene, std::string_view model) {
  if (scene.shapes.size() != 1 || scene.shapes[0].kind != Shape::Kind::Sphere)
    refuse(scene, model, "needs exactly one shape, a sphere");
  if (!scene.delta_lights.empty()) refuse(scene, model, "delta lights (point, spot, directional) break the uniform surroundings; remove them");
  if (!scene.environment) refuse(scene, model, "needs a uniform environment light");
  if (scene.materials[scene.shapes[0].material].emits()) refuse(scene, model, "the sphere must not emit");
  if (scene.materials[scene.shapes[0].material].one_sided && scene.shapes[0].flip_normals)
    refuse(scene, model, "a one-sided sphere whose front faces in is black from outside: nothing to check");
  return scene.shapes[0];
}

// Cosine of the angle between the camera ray and the sphere's normal where
// it hits, if it does.
std::optional<float> view_cosine(const vec3& center, float radius, const Ray& ray) {
  const auto t = hit_sphere(center, radius, ray);
  if (!t) return std::nullopt;
  const dvec3 p = dvec3(ray.origin) + *t * glm::normalize(dvec3(ray.dir));
  const dvec3 n = glm::normalize(p - dvec3(center));
  return static_cast<float>(std::clamp(-glm::dot(glm::normalize(dvec3(ray.dir)), n), 0.0, 1.0));
}

class RoughSphere final : public AnalyticModel {
 public:
  static constexpr int kTable = 65;
  RoughSphere(const Shape& s, Spectrum L, const Material& m, int depth, std::string description)
      : center_(s.center), radius_(s.radius), L_(L), description_(std::move(description)) {
    // The table depends only on the material and the depth cap: computed
    // once per process (checks render the same scene under every strategy).
    static std::mutex mutex;
    static std::map<std::vector<float>, std::array<Spectrum, kTable>> cache;
    const DisneyParams& q = m.disney;
    const std::vector<float> key{q.base_color.x, q.base_color.y, q.base_color.z, q.metallic, q.subsurface, q.specular,
                                 q.specular_tint, q.roughness, q.sheen, q.sheen_tint, q.clearcoat, q.clearcoat_gloss,
                                 q.energy_compensation ? 1.0f : 0.0f, depth == 0 ? 0.0f : 1.0f};
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto it = cache.find(key); it != cache.end()) {
      albedo_ = it->second;
      return;
    }
    const disney::Closure c = disney::make_closure(m.disney);
    for (int i = 0; i < kTable; ++i) {
      const float mu = static_cast<float>(i) / (kTable - 1);
      const vec3 wo(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu);
      const std::vector<quadrature::Peak> peaks{{vec3(-wo.x, 0.0f, wo.z), static_cast<double>(c.ax),
                                                 std::max(1e-4, static_cast<double>(mu)) * c.ax}};
      Spectrum a(0.0f);
      if (depth != 0 && mu > 0.0f)
        a = Spectrum(quadrature::integrate_directions(
            [&](const vec3& wi) { return dvec3(disney::eval<disney::kGeneral>(c, wo, wi)); }, peaks, 1e-6, 4, 8));
      albedo_[i] = a;
    }
    cache[key] = albedo_;
  }
  std::string_view name() const override { return "rough-sphere-in-environment"; }
  Spectrum radiance(const Ray& ray) const override {
    const auto mu = view_cosine(center_, radius_, ray);
    if (!mu) return L_;
    const float x = *mu * (kTable - 1);
    const int i = std::min(kTable - 2, static_cast<int>(x));
    return L_ * glm::mix(albedo_[i], albedo_[i + 1], x - static_cast<float>(i));
  }
  // The sphere's silhouette; inside it the radiance is a continuous
  // function of the view cosine, outside it uniform.
  void edges(EdgeList& out) const override { out.sphere_silhouette(dvec3(center_), radius_); }
  std::string describe() const override { return description_; }

 private:
  vec3 center_;
  float radius_;
  Spectrum L_;
  std::array<Spectrum, kTable> albedo_;
  std::string description_;
};

class GlassSphere final : public AnalyticModel {
 public:
  GlassSphere(const Shape& s, Spectrum L, const DielectricParams& g, int depth, std::string description)
      : center_(s.center), radius_(s.radius), L_(L), glass_(g), depth_(depth), description_(std::move(description)) {}
  std::string_view name() const override { return "glass-sphere-in-environment"; }
  Spectrum radiance(const Ray& ray) const override {
    const auto mu = view_cosine(center_, radius_, ray);
    if (!mu) return L_;
    if (depth_ == 0) return Spectrum(0.0f);
    const double F = fresnel::dielectric(*mu, glass_.ior);
    Spectrum out;
    for (int k = 0; k < 3; ++k) {
      const double R = glass_.reflectance[k], T = glass_.transmittance[k], rf = R * F;
      // sum_{j=0}^{D-2} (RF)^j, or to infinity (RF < 1 unless mu = 0 and R = 1).
      const double series = depth_ < 0 ? (rf < 1.0 ? 1.0 / (1.0 - rf) : 0.0)
                                       : (depth_ < 2 ? 0.0 : (rf == 1.0 ? depth_ - 1.0 : (1.0 - std::pow(rf, depth_ - 1)) / (1.0 - rf)));
      out[k] = static_cast<float>(L_[k] * (rf + T * T * (1.0 - F) * (1.0 - F) * series));
    }
    return out;
  }
  // The sphere's silhouette; inside it the radiance is a continuous
  // function of the view cosine, outside it uniform.
  void edges(EdgeList& out) const override { out.sphere_silhouette(dvec3(center_), radius_); }
  std::string describe() const override { return description_; }

 private:
  vec3 center_;
  float radius_;
  Spectrum L_;
  DielectricParams glass_;
  int depth_;
  std::string description_;
};

}  // namespace

std::unique_ptr<AnalyticModel> make_rough_sphere_in_environment(const Scene& scene) {
  constexpr std::string_view kName = "rough-sphere-in-environment";
  const Shape& s = lone_sphere(scene, kName);
  const Material& m = scene.materials[s.material];
  if (m.type != MaterialType::Disney) refuse(scene, kName, "the sphere must be a disney material");
  if (m.disney.anisotropic != 0.0f)
    refuse(scene, kName, "the sphere must be isotropic (anisotropic 0): the albedo would depend on the tangent frame");
  const int D = scene.render.max_depth;
  std::ostringstream d;
  d << "disney sphere '" << m.name << "' base_color " << fmt(m.disney.base_color) << " metallic " << m.disney.metallic
    << " roughness " << m.disney.roughness << (m.disney.clearcoat > 0.0f ? ", clear-coated" : "")
    << (m.disney.energy_compensation ? ", energy-compensated" : "") << " in environment " << fmt(*scene.environment)
    << ", depth cap " << D
    << ": L x directional albedo by quadrature";
  return std::make_unique<RoughSphere>(s, *scene.environment, m, D, d.str());
}

std::unique_ptr<AnalyticModel> make_glass_sphere_in_environment(const Scene& scene) {
  constexpr std::string_view kName = "glass-sphere-in-environment";
  const Shape& s = lone_sphere(scene, kName);
  const Material& m = scene.materials[s.material];
  if (m.type != MaterialType::Dielectric) refuse(scene, kName, "the sphere must be a dielectric material");
  if (s.flip_normals) refuse(scene, kName, "the sphere's outside must be its front (no flip_normals)");
  const int D = scene.render.max_depth;
  std::ostringstream d;
  d << "glass sphere '" << m.name << "' ior " << m.glass.ior << " reflectance " << fmt(m.glass.reflectance)
    << " transmittance " << fmt(m.glass.transmittance) << " in environment " << fmt(*scene.environment) << ", depth cap "
    << D;
  return std::make_unique<GlassSphere>(s, *scene.environment, m.glass, D, d.str());
}

}  // namespace pathlab::analytic
