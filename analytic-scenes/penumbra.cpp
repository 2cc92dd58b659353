// Model "penumbra": a planar convex emitter of radiance Le (one-sided unless
// two_sided), a planar Lambert ground of albedo rho (black from behind if its
// material is one_sided), and at most one black occluder strictly between
// the emitter's plane and the ground: a closed convex mesh (a box) or a
// planar convex polygon (a quad), of coverage alpha (core/alpha.h; 1 if its
// material has none). Nothing else reflects, so a ground point x receives
// direct light only:
//   L(x) = rho / pi * Le * FF(x),
//   FF(x) = F(emitter) - o F(emitter ∩ shadow(x)),
// with F the cosine-weighted solid angle of a polygon seen from x (Lambert's
// formula after clipping to x's horizon, polygon_irradiance.h), shadow(x)
// the occluder projected from x onto the emitter's plane: convex, because
// the occluder is, and exactly the set of emitter points whose segment to x
// meets it; and o the probability that such a segment is stopped: alpha
// for a polygon, which the segment crosses once, 1 - (1 - alpha)^2 for a
// closed mesh, which it crosses twice, each crossing decided independently.
// With alpha = 1, o = 1: umbra (FF = 0), penumbra and fully lit points are
// all exact; with alpha < 1 the irradiance is E_unoccluded - o (E_unoccluded
// - E_occluded), as exact.
//
// A camera ray carries: Le where it meets the emitter's front, 0 on the
// occluder or the emitter's back or when it escapes, and L(x) on the ground
// (0 with a depth cap of 0); a ray that meets the occluder passes it with
// probability 1 - o and carries what lies behind, so its expected radiance
// is (1 - o) times that. The same model serves the emitter registered
// as a light and, with "light": false in its material, as a plain emissive
// surface only BSDF sampling finds.
#include "analytic-scenes/models.h"
#include "analytic-scenes/polygon_irradiance.h"
#include "analytic-scenes/room.h"
#include "core/geometry.h"

#include <sstream>

namespace pathlab::analytic {
namespace {

struct Plane {
  dvec3 point, normal;  // unit normal
  double distance(const dvec3& p) const { return glm::dot(p - point, normal); }
};

// The plane of a triangle mesh's first triangle, if every vertex lies in it
// (relative tolerance 1e-6 of the mesh's extent).
std::optional<Plane> plane_of(const Shape& s) {
  if (s.kind != Shape::Kind::Triangles || s.mesh.triangles.empty()) return std::nullopt;
  const Plane p{dvec3(s.mesh.positions[s.mesh.triangles[0].x]), dvec3(triangle_normal(s, 0))};
  double extent = 0.0;
  for (const vec3& v : s.mesh.positions) extent = std::max(extent, glm::length(dvec3(v) - p.point));
  for (const vec3& v : s.mesh.positions)
    if (std::abs(p.distance(dvec3(v))) > 1e-6 * extent) return std::nullopt;
  return p;
}

double mesh_area(const Shape& s) {
  double a = 0.0;
  for (std::uint32_t t = 0; t < s.mesh.triangles.size(); ++t) a += triangle_area(s.mesh, t);
  return a;
}

// True if every vertex lies on the inner side of every face's plane.
bool is_convex(const Shape& s) {
  double extent = 0.0;
  for (const vec3& v : s.mesh.positions) extent = std::max<double>(extent, glm::length(v - s.mesh.positions[0]));
  const dvec3 centre = [&] {
    dvec3 c(0.0);
    for (const vec3& v : s.mesh.positions) c += dvec3(v);
    return c / static_cast<double>(s.mesh.positions.size());
  }();
  for (std::uint32_t t = 0; t < s.mesh.triangles.size(); ++t) {
    const dvec3 p(s.mesh.positions[s.mesh.triangles[t].x]);
    dvec3 n(triangle_normal(s, t));
    if (glm::dot(n, centre - p) > 0.0) n = -n;  // point n outwards
    for (const vec3& v : s.mesh.positions)
      if (glm::dot(dvec3(v) - p, n) > 1e-6 * extent) return false;
  }
  return true;
}

// Nearest triangle hit in double precision: the shape index and distance.
std::optional<std::pair<std::size_t, double>> nearest_hit(const std::vector<const Shape*>& shapes, const Ray& ray) {
  const dvec3 o(ray.origin), d = glm::normalize(dvec3(ray.dir));
  std::optional<std::pair<std::size_t, double>> best;
  for (std::size_t i = 0; i < shapes.size(); ++i)
    for (const glm::uvec3& t : shapes[i]->mesh.triangles) {
      const TriangleMesh& m = shapes[i]->mesh;
      const auto dist = hit_triangle(o, d, dvec3(m.positions[t.x]), dvec3(m.positions[t.y]), dvec3(m.positions[t.z]));
      if (dist && (!best || *dist < best->second)) best = std::pair{i, *dist};
    }
  return best;
}

class Penumbra final : public AnalyticModel {
 public:
  const Shape* emitter = nullptr;
  const Shape* ground = nullptr;
  const Shape* occluder = nullptr;  // may be null
  double opacity = 1.0;              // o: the probability that a segment through the occluder is stopped
  Plane emitter_plane, ground_plane;
  dvec3 eu, ev;                      // basis of the emitter's plane
  std::vector<glm::dvec2> emitter_2d;  // convex, counter-clockwise
  std::vector<dvec3> emitter_3d;
  Spectrum Le{0.0f}, rho{0.0f};
  bool two_sided = false;         // the emitter's emission
  bool ground_one_sided = false;  // the ground's reflection
  int max_depth = 0;
  std::string description;

  std::string_view name() const override { return "penumbra"; }
  std::string describe() const override { return description; }

  glm::dvec2 to_2d(const dvec3& p) const { return {glm::dot(p - emitter_plane.point, eu), glm::dot(p - emitter_plane.point, ev)}; }
  dvec3 to_3d(const glm::dvec2& p) const { return emitter_plane.point + p.x * eu + p.y * ev; }

  // Cosine-weighted solid angle of the part of the emitter that x sees.
  double visible_form_factor(const dvec3& x, const dvec3& n) const {
    if (!two_sided && emitter_plane.distance(x) <= 0.0) return 0.0;  // behind a one-sided emitter
    double ff = polygon_form_factor(emitter_3d, x, n);
    if (occluder && ff > 0.0) {
      std::vector<glm::dvec2> shadow;
      const double hx = emitter_plane.distance(x);
      for (const vec3& v : occluder->mesh.positions) {
        // Central projection from x through v onto the emitter's plane.
        const dvec3 dv = dvec3(v) - x;
        const double t = -hx / glm::dot(dv, emitter_plane.normal);
        shadow.push_back(to_2d(x + t * dv));
      }
      const std::vector<glm::dvec2> hidden = clip_convex(convex_hull(std::move(shadow)), emitter_2d);
      if (!hidden.empty()) {
        std::vector<dvec3> hidden_3d;
        for (const glm::dvec2& p : hidden) hidden_3d.push_back(to_3d(p));
        ff -= opacity * polygon_form_factor(hidden_3d, x, n);
      }
    }
    return std::max(0.0, ff);
  }

  Spectrum radiance(const Ray& ray) const override {
    std::vector<const Shape*> shapes{emitter, ground};
    if (occluder) shapes.push_back(occluder);
    auto hit = nearest_hit(shapes, ray);
    // The occluder is black: it stops a ray with probability o and gives 0;
    // otherwise the ray goes on to what lies behind it.
    float through = 1.0f;
    if (hit && hit->first == 2) {
      through = static_cast<float>(1.0 - opacity);
      shapes.pop_back();
      hit = nearest_hit(shapes, ray);
    }
    if (!hit || through == 0.0f) return Spectrum(0.0f);
    const dvec3 d = glm::normalize(dvec3(ray.dir));
    const dvec3 x = dvec3(ray.origin) + hit->second * d;
    if (hit->first == 0) return (two_sided || glm::dot(d, emitter_plane.normal) < 0.0) ? through * Le : Spectrum(0.0f);
    if (max_depth == 0) return Spectrum(0.0f);
    // A two-sided Lambert ground shades on the camera's side; a one-sided
    // one is black from behind.
    const bool front = glm::dot(d, ground_plane.normal) < 0.0;
    if (ground_one_sided && !front) return Spectrum(0.0f);
    const dvec3 n = front ? ground_plane.normal : -ground_plane.normal;
    return through * rho * Le * static_cast<float>(visible_form_factor(x, n) / kPi);
  }
};

}  // namespace

std::unique_ptr<AnalyticModel> make_penumbra(const Scene& scene) {
  constexpr std::string_view kName = "penumbra";
  auto model = std::make_unique<Penumbra>();
  for (const Shape& s : scene.shapes) {
    const Material& m = scene.materials[s.material];
    if (m.emits()) {
      if (model->emitter) refuse(scene, kName, "needs exactly one emitting shape; found two");
      model->emitter = &s;
    } else if (!is_black(m.albedo)) {
      if (model->ground) refuse(scene, kName, "needs exactly one reflecting shape, the ground; found two");
      model->ground = &s;
    } else {
      if (model->occluder) refuse(scene, kName, "allows at most one black occluder (their shadows would overlap)");
      model->occluder = &s;
    }
  }
  if (!model->emitter) refuse(scene, kName, "needs an emitting polygon");
  if (!model->ground) refuse(scene, kName, "needs a reflecting ground");
  if ((scene.environment && !is_black(*scene.environment)) || scene.environment_map)
    refuse(scene, kName, "an environment would light the ground too; remove it");
  if (!scene.delta_lights.empty()) refuse(scene, kName, "delta lights (point, spot, directional) would light the ground too; remove them");

  const Material& em = scene.materials[model->emitter->material];
  const Material& gm = scene.materials[model->ground->material];
  if (gm.has_alpha()) refuse(scene, kName, "only the occluder may have alpha (the ground has)");
  if (em.scatters()) refuse(scene, kName, "the emitter must reflect nothing (material type \"emissive\")");
  if (gm.type != MaterialType::Diffuse) refuse(scene, kName, "the ground must be diffuse (Lambert)");
  const auto ep = plane_of(*model->emitter);
  if (!ep) refuse(scene, kName, "the emitter must be planar (a rectangle or a planar mesh)");
  const auto gp = plane_of(*model->ground);
  if (!gp) refuse(scene, kName, "the ground must be planar");
  model->emitter_plane = *ep;
  model->ground_plane = *gp;

  // The emitter as a convex polygon in its plane: the hull of its vertices,
  // which must have the mesh's own area (else it is not convex).
  const Frame f{vec3(ep->normal)};
  model->eu = dvec3(f.s);
  model->ev = dvec3(f.t);
  std::vector<glm::dvec2> pts;
  for (const vec3& v : model->emitter->mesh.positions) pts.push_back(model->to_2d(dvec3(v)));
  model->emitter_2d = convex_hull(std::move(pts));
  if (std::abs(signed_area(model->emitter_2d) - mesh_area(*model->emitter)) > 1e-5 * mesh_area(*model->emitter))
    refuse(scene, kName, "the emitter must be a convex polygon");
  for (const glm::dvec2& p : model->emitter_2d) model->emitter_3d.push_back(model->to_3d(p));

  if (const Shape* occ = model->occluder) {
    // A closed convex mesh, or a planar convex polygon (its hull in its
    // plane has the mesh's own area).
    const auto planar = occ->kind == Shape::Kind::Triangles ? plane_of(*occ) : std::nullopt;
    bool convex_polygon = false;
    if (planar) {
      const Frame pf{vec3(planar->normal)};
      std::vector<glm::dvec2> hull;
      for (const vec3& v : occ->mesh.positions)
        hull.emplace_back(glm::dot(dvec3(v) - planar->point, dvec3(pf.s)), glm::dot(dvec3(v) - planar->point, dvec3(pf.t)));
      hull = convex_hull(std::move(hull));
      convex_polygon = std::abs(signed_area(hull) - mesh_area(*occ)) <= 1e-5 * mesh_area(*occ);
    }
    if (occ->kind != Shape::Kind::Triangles || !(convex_polygon || (is_closed(*occ) && is_convex(*occ))))
      refuse(scene, kName, "the occluder must be a closed convex mesh (a box) or a planar convex polygon (a quad)");
    if (scene.materials[occ->material].alpha_texture)
      refuse(scene, kName, "the occluder's alpha must be a number (an alpha texture is not modelled)");
    const double a = scene.materials[occ->material].alpha;
    model->opacity = convex_polygon ? a : 1.0 - (1.0 - a) * (1.0 - a);
    // Strictly between the emitter's plane and the whole ground, so that from
    // every ground point it projects onto the emitter's plane.
    double ground_near = kInfinity;
    for (const vec3& v : model->ground->mesh.positions) ground_near = std::min(ground_near, ep->distance(dvec3(v)));
    for (const vec3& v : occ->mesh.positions) {
      const double h = ep->distance(dvec3(v));
      if (!(h > 0.0 && h < ground_near))
        refuse(scene, kName, "the occluder must lie strictly between the emitter's front and the ground");
    }
  }
  model->Le = em.emission;
  model->rho = gm.albedo;
  model->two_sided = em.two_sided_emission;
  model->ground_one_sided = gm.one_sided;
  model->max_depth = scene.render.max_depth;
  std::ostringstream d;
  d << "emitter '" << em.name << "' Le (" << em.emission.x << ", " << em.emission.y << ", " << em.emission.z << ")"
    << (em.sampled_as_light ? " as a light" : " not a light (BSDF sampling only)") << ", ground '" << gm.name
    << "' albedo (" << gm.albedo.x << ", " << gm.albedo.y << ", " << gm.albedo.z << ")"
    << (gm.one_sided ? " one-sided" : "")
    << (model->occluder ? ", one occluder" : ", no occluder");
  if (model->occluder && scene.materials[model->occluder->material].has_alpha())
    d << " of alpha " << scene.materials[model->occluder->material].alpha << " (stops " << model->opacity
      << " of the segments through it)";
  d << ", depth cap " << model->max_depth;
  model->description = d.str();
  return model;
}

}  // namespace pathlab::analytic
