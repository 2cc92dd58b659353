// Model "penumbra": a planar convex emitter of radiance Le (one-sided unless
// two_sided), a planar Lambert ground of albedo rho (black from behind if its
// material is one_sided), and at most one black occluder strictly between
// the emitter's plane and the ground: a closed convex mesh (a box) or a
// planar convex polygon (a quad), of coverage alpha (core/alpha.h; 1 if its
// material has none) - or a planar quad whose alpha texture is a mask (0 or
// 1 at every texel, read linear) opaque on a rectangle of texels: a convex
// cut-out, which the model takes as the occluder (alpha 1), its corners
// where the texel edges lie on the quad. Nothing else reflects, so a ground point x receives
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
#include "core/image_io.h"

#include <algorithm>

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
  Shape cutout;                      // the opaque part of an occluder with an alpha mask
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
  // The outlines of the emitter, the ground and the occluder. The shadow's
  // edges need nothing: lit by an area emitter, the ground's radiance is
  // continuous across them (only its derivative jumps).
  void edges(EdgeList& out) const override {
    out.mesh_edges(*emitter);
    out.mesh_edges(*ground);
    if (occluder) out.mesh_edges(*occluder);
  }

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

// The opaque part of the planar occluder `occ`, whose material's alpha is a
// texture: every texel 0 or 1 (after scale, offset and the cutoff), the 1s
// a rectangle of texels. Read at the nearest texel (core/alpha.h), texel
// (x, y) from the top covers u in [x, x + 1) / W and v in (1 - (y + 1) / H,
// 1 - y / H]; the quad's uvs map affinely onto it. Nothing if no texel is
// opaque.
std::optional<Shape> opaque_part(const Scene& scene, const Shape& occ, std::string_view name) {
  const Material& m = scene.materials[occ.material];
  const TextureRef& ref = *m.alpha_texture;
  const TextureImage& image = scene.textures[ref.image];
  if (image.colorspace != TextureColorSpace::Linear) refuse(scene, name, "the occluder's alpha texture must be linear");
  if (ref.channel > 2) refuse(scene, name, "the occluder's alpha must be one of the texture's first three channels");
  if (!occ.mesh.has_uvs() || occ.mesh.triangles.size() != 2)
    refuse(scene, name, "an occluder with an alpha texture must be a quad with texture coordinates (a rectangle)");
  const Image texels = read_image(image.file);
  const int w = texels.width, h = texels.height;
  int x0 = w, x1 = -1, y0 = h, y1 = -1;
  std::vector<bool> opaque(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float a = std::clamp(ref.scale.x * texels.at(x, y)[ref.channel] + ref.offset.x, 0.0f, 1.0f);
      if (m.alpha_cutoff >= 0.0f) a = a >= m.alpha_cutoff ? 1.0f : 0.0f;
      if (a != 0.0f && a != 1.0f)
        refuse(scene, name, "the occluder's alpha texture must be a mask, 0 or 1 at every texel (texel (" +
                                std::to_string(x) + ", " + std::to_string(y) + ") is " + std::to_string(a) + ")");
      if (a == 1.0f) {
        opaque[static_cast<std::size_t>(y) * w + x] = true;
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    }
  if (x1 < 0) return std::nullopt;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x)
      if (!opaque[static_cast<std::size_t>(y) * w + x])
        refuse(scene, name, "the opaque texels of the occluder's alpha texture must form a rectangle (a convex cut-out)");
  // p(uv) = p0 + A (uv - uv0), from the first triangle.
  const glm::uvec3 t = occ.mesh.triangles[0];
  const dvec3 p0(occ.mesh.positions[t.x]), e1 = dvec3(occ.mesh.positions[t.y]) - p0, e2 = dvec3(occ.mesh.positions[t.z]) - p0;
  const glm::dvec2 uv0(occ.mesh.uvs[t.x]), d1 = glm::dvec2(occ.mesh.uvs[t.y]) - uv0, d2 = glm::dvec2(occ.mesh.uvs[t.z]) - uv0;
  const double det = d1.x * d2.y - d1.y * d2.x;
  if (std::abs(det) < 1e-12) refuse(scene, name, "the occluder's texture coordinates are degenerate");
  const auto at = [&](double u, double v) {
    const glm::dvec2 d(u - uv0.x, v - uv0.y);
    const double a = (d.x * d2.y - d.y * d2.x) / det, b = (d1.x * d.y - d1.y * d.x) / det;
    return vec3(p0 + a * e1 + b * e2);
  };
  const double u_lo = static_cast<double>(x0) / w, u_hi = static_cast<double>(x1 + 1) / w;
  const double v_lo = 1.0 - static_cast<double>(y1 + 1) / h, v_hi = 1.0 - static_cast<double>(y0) / h;
  Shape part = occ;
  part.description = occ.description + " (its opaque texels)";
  part.mesh = TriangleMesh{};
  part.mesh.positions = {at(u_lo, v_lo), at(u_hi, v_lo), at(u_hi, v_hi), at(u_lo, v_hi)};
  part.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return part;
}

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
    if (scene.materials[occ->material].alpha_texture) {
      if (!convex_polygon) refuse(scene, kName, "an alpha texture is modelled on a planar occluder (a quad) only");
      model->opacity = 1.0;
    } else {
      const double a = scene.materials[occ->material].alpha;
      model->opacity = convex_polygon ? a : 1.0 - (1.0 - a) * (1.0 - a);
    }
    // Strictly between the emitter's plane and the whole ground, so that from
    // every ground point it projects onto the emitter's plane.
    double ground_near = kInfinity;
    for (const vec3& v : model->ground->mesh.positions) ground_near = std::min(ground_near, ep->distance(dvec3(v)));
    for (const vec3& v : occ->mesh.positions) {
      const double h = ep->distance(dvec3(v));
      if (!(h > 0.0 && h < ground_near))
        refuse(scene, kName, "the occluder must lie strictly between the emitter's front and the ground");
    }
    if (scene.materials[occ->material].alpha_texture) {
      const std::optional<Shape> part = opaque_part(scene, *occ, kName);
      model->occluder = nullptr;  // a mask that is clear everywhere occludes nothing
      if (part) {
        model->cutout = *part;
        model->occluder = &model->cutout;
      }
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
  if (model->occluder == &model->cutout)
    d << " cut out by its alpha mask to the quad of its opaque texels";
  else if (model->occluder && scene.materials[model->occluder->material].has_alpha())
    d << " of alpha " << scene.materials[model->occluder->material].alpha << " (stops " << model->opacity
      << " of the segments through it)";
  d << ", depth cap " << model->max_depth;
  model->description = d.str();
  return model;
}

}  // namespace pathlab::analytic
