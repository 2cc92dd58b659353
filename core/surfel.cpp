#include "core/surfel.h"

#include "core/bsdf/dielectric.h"
#include "core/bsdf/disney.h"
#include "core/bsdf/lambert.h"
#include "core/bsdf/mirror.h"
#include "core/faults.h"
#include "core/geometry.h"
#include "core/sampling.h"
#include "core/simd/width1.h"

namespace pathlab {
namespace {

// The reflection models are two-sided: flip the local frame so that wo is
// on +z. (The dielectric is not: it reads the side from the geometric normal.)
struct LocalDirs {
  vec3 wo, wi;
};
LocalDirs to_local_upper(const Frame& frame, const vec3& wo, const vec3& wi) {
  using namespace width1;
  F3 wo_local, wi_local;
  generic::to_local_upper(kScalar, lanes(frame.s), lanes(frame.t), lanes(frame.n), lanes(wo), lanes(wi), wo_local,
                          wi_local);
  return {scalars(wo_local), scalars(wi_local)};
}

// What shading reads of a material: its own constants, or the parameters
// a textured material has at this point (Surfel::params). The same names as
// Material's fields, so the code below reads either.
struct MaterialView {
  MaterialType type;
  const ShadingConfig& shading;
  const Spectrum& albedo;
  const disney::Closure& closure;
  const DielectricParams& glass;
};
MaterialView view_of(const Material& m, const SurfaceParams* p) {
  if (p == nullptr) return {m.type, m.shading, m.albedo, m.closure, m.glass};
  return {m.type, m.shading, p->albedo, p->closure, p->glass};
}

using disney::kClearcoat;
using disney::kDisneyLobes;
using disney::kGeneral;

// Shading specialised to a feature set (disney::Features); 0 = the
// Lambert-only path, which contains no Disney code at all. In the general
// path a "diffuse" material goes through the closure too.
template <unsigned F> bool via_closure(const MaterialView& m) {
  if constexpr (F == 0) return false;
  else if constexpr ((F & disney::kLambertLobe) != 0) return m.type == MaterialType::Disney || m.type == MaterialType::Diffuse;
  else return m.type == MaterialType::Disney;
}

template <unsigned F> Spectrum eval_as(const MaterialView& m, const LocalDirs& d) {
  if constexpr (F != 0) {
    if (via_closure<F>(m)) return disney::eval<F>(m.closure, d.wo, d.wi);
  }
  if (m.type != MaterialType::Diffuse) return Spectrum(0.0f);
  if (PATHLAB_FAULT(CosineDropped)) return d.wi.z > 0.0f ? m.albedo * kInvPi : Spectrum(0.0f);
  return lambert::eval(m.albedo, d.wi);
}

template <unsigned F> float pdf_as(const MaterialView& m, const LocalDirs& d) {
  if constexpr (F != 0) {
    if (via_closure<F>(m)) return disney::pdf<F>(m.closure, d.wo, d.wi, m.shading.sampling);
  }
  if (m.type != MaterialType::Diffuse) return 0.0f;
  if (PATHLAB_FAULT(BsdfPdfOff5Percent)) return 1.05f * lambert::pdf(d.wi);
  return lambert::pdf(d.wi);
}

template <unsigned F>
std::optional<BsdfSample> scatter_closure(const MaterialView& m, const Frame& frame, const vec3& wo_local, float side,
                                          float u_lobe, vec2 u) {
  const std::optional<disney::Scatter> ds =
      disney::scatter<F>(m.closure, wo_local, u_lobe, u, m.shading.sampling, m.shading.min_pdf);
  if (!ds) return std::nullopt;
  vec3 wi = ds->wi;
  wi.z *= side;
  return BsdfSample{frame.to_world(wi), ds->weight, ds->pdf, ds->lobe, false};
}

std::optional<BsdfSample> scatter_dielectric(const MaterialView& m, const Frame& frame, const vec3& wo, float u_lobe) {
  // The geometric normal's side is the outside: entering or leaving decides
  // eta (dielectric.h).
  dielectric::Sample ds;
  if (!dielectric::sample(m.glass, u_lobe, frame.to_local(wo), &ds, PATHLAB_FAULT(DielectricFresnelIgnored)))
    return std::nullopt;
  return BsdfSample{frame.to_world(ds.wi), ds.weight, ds.pdf,
                    ds.transmitted ? Lobe::DielectricTransmission : Lobe::DielectricReflection, true};
}

// Surfel's rules around the BSDFs at width 1 (core/simd/lanes-inl.h's
// surface_eval_ok, surface_scatter_ok and scattered_side_ok, which the
// wavefront's lanes apply too): the one-sided policy, and the shading-normal
// policy (surfel.h): with a shading normal, a reflection needs wi and wo on
// the same side of the geometric surface, a transmission opposite sides.
// Without one the shading frame is the geometric frame and the lobes' own
// hemisphere tests already say the same.
bool eval_ok(const Surfel& s, const vec3& wi, const vec3& wo) {
  if (!s.material->one_sided && !s.shading_normal) return true;  // as the lanes skip it
  using namespace width1;
  return generic::surface_eval_ok(kScalar, lane1::M{s.material->one_sided}, lane1::M{s.shading_normal},
                                  F{glm::dot(wo, s.n)}, F{glm::dot(wi, s.n)})
      .raw;
}
bool scatter_ok(const Surfel& s, const vec3& wo) {
  const bool dielectric = s.material->type == MaterialType::Dielectric;
  if (!s.material->one_sided && !(dielectric && s.shading_normal)) return true;
  using namespace width1;
  return generic::surface_scatter_ok(kScalar, lane1::M{s.material->one_sided},
                                     lane1::M{dielectric && s.shading_normal}, F{glm::dot(wo, s.n)},
                                     F{glm::dot(wo, s.frame.n)})
      .raw;
}
// The side the reflection models see wo from (its z in the shading frame: wo_fz).
float upper_side(float wo_fz) {
  using namespace width1;
  return generic::upper_side(kScalar, F{wo_fz}).raw;
}
bool scattered_ok(const Surfel& s, const vec3& wi, const vec3& wo, bool transmitted) {
  if (!s.shading_normal) return true;
  using namespace width1;
  return generic::scattered_side_ok(kScalar, lane1::M{s.shading_normal}, lane1::M{transmitted}, F{glm::dot(wo, s.n)},
                                    F{glm::dot(wi, s.n)})
      .raw;
}

}  // namespace

Spectrum Surfel::emitted(const vec3& wo) const {
  if (!material->emits()) return Spectrum(0.0f);
  using namespace width1;
  return scalars(generic::emitted_towards(kScalar, lane1::M{material->two_sided_emission}, lanes(n), lanes(wo),
                                          lanes(params ? params->emission : material->emission)));
}

Spectrum Surfel::eval(const vec3& wi, const vec3& wo) const {
  if (material->is_pure_impulse() || material->type == MaterialType::Emissive) return Spectrum(0.0f);
  if (!eval_ok(*this, wi, wo)) return Spectrum(0.0f);
  const MaterialView m = view_of(*material, params);
  const LocalDirs d = to_local_upper(frame, wo, wi);
  switch (m.shading.path) {
    case ShadingPath::LambertOnly: return eval_as<0>(m, d);
    case ShadingPath::Disney: return eval_as<kDisneyLobes>(m, d);
    case ShadingPath::DisneyClearcoat: return eval_as<kDisneyLobes | kClearcoat>(m, d);
    case ShadingPath::General: return eval_as<kGeneral>(m, d);
  }
  return Spectrum(0.0f);
}

float Surfel::pdf(const vec3& wi, const vec3& wo) const {
  if (material->is_pure_impulse() || material->type == MaterialType::Emissive) return 0.0f;
  if (!scatter_ok(*this, wo)) return 0.0f;  // scatter() samples nothing there
  const MaterialView m = view_of(*material, params);
  const LocalDirs d = to_local_upper(frame, wo, wi);
  switch (m.shading.path) {
    case ShadingPath::LambertOnly: return pdf_as<0>(m, d);
    case ShadingPath::Disney: return pdf_as<kDisneyLobes>(m, d);
    case ShadingPath::DisneyClearcoat: return pdf_as<kDisneyLobes | kClearcoat>(m, d);
    case ShadingPath::General: return pdf_as<kGeneral>(m, d);
  }
  return 0.0f;
}

std::optional<BsdfSample> Surfel::scatter(const vec3& wo, float u_lobe, vec2 u) const {
  if (!scatter_ok(*this, wo)) return std::nullopt;
  std::optional<BsdfSample> s = scatter_in_frame(wo, u_lobe, u);
  if (s && !scattered_ok(*this, s->wi, wo, s->lobe == Lobe::DielectricTransmission)) return std::nullopt;
  return s;
}

std::optional<BsdfSample> Surfel::scatter_in_frame(const vec3& wo, float u_lobe, vec2 u) const {
  const MaterialView m = view_of(*material, params);
  if (m.type == MaterialType::Dielectric) return scatter_dielectric(m, frame, wo, u_lobe);
  vec3 wo_local = frame.to_local(wo);
  const float side = upper_side(wo_local.z);
  wo_local.z *= side;
  switch (m.shading.path) {
    case ShadingPath::LambertOnly: break;
    case ShadingPath::Disney:
      if (via_closure<kDisneyLobes>(m)) return scatter_closure<kDisneyLobes>(m, frame, wo_local, side, u_lobe, u);
      break;
    case ShadingPath::DisneyClearcoat:
      if (via_closure<kDisneyLobes | kClearcoat>(m))
        return scatter_closure<kDisneyLobes | kClearcoat>(m, frame, wo_local, side, u_lobe, u);
      break;
    case ShadingPath::General:
      if (via_closure<kGeneral>(m)) return scatter_closure<kGeneral>(m, frame, wo_local, side, u_lobe, u);
      break;
  }
  switch (m.type) {
    case MaterialType::Diffuse: {
      vec3 wi;
      float pdf;
      if (!lambert::sample(u, m.shading.min_pdf, &wi, &pdf)) return std::nullopt;
      wi.z *= side;
      if (PATHLAB_FAULT(BsdfPdfOff5Percent) || PATHLAB_FAULT(CosineDropped)) {
        const vec3 w = frame.to_world(wi);
        const float faulty_pdf = this->pdf(w, wo);
        return BsdfSample{w, eval(w, wo) / faulty_pdf, faulty_pdf, Lobe::Lambert, false};
      }
      return BsdfSample{frame.to_world(wi), m.albedo, pdf, Lobe::Lambert, false};
    }
    case MaterialType::Mirror: {
      // Chosen with probability equal to its mean reflectance (mirror.h).
      vec3 wi;
      Spectrum weight;
      float prob;
      if (!mirror::sample(m.albedo, u_lobe, wo_local, &wi, &weight, &prob)) return std::nullopt;
      wi.z *= side;
      return BsdfSample{frame.to_world(wi), weight, prob, Lobe::MirrorImpulse, true};
    }
    case MaterialType::Disney:       // only reached with a path that cannot shade it (never configured so)
    case MaterialType::Dielectric:   // handled above
    case MaterialType::Emissive: return std::nullopt;
  }
  return std::nullopt;
}

std::optional<BsdfSample> Surfel::scatter_cosine(const vec3& wo, vec2 u) const {
  if (material->is_pure_impulse() || !scatter_ok(*this, wo)) return std::nullopt;
  const float side = upper_side(glm::dot(wo, frame.n));
  vec3 wi_local = square_to_cosine_hemisphere(u);
  const float pdf = cosine_hemisphere_pdf(wi_local);
  if (pdf <= 0.0f) return std::nullopt;
  wi_local.z *= side;
  const vec3 wi = frame.to_world(wi_local);
  if (!scattered_ok(*this, wi, wo, false)) return std::nullopt;
  return BsdfSample{wi, eval(wi, wo) / pdf, pdf, Lobe::Lambert, false};
}

Ray Surfel::spawn(const vec3& dir) const {
  using namespace width1;
  return Ray{scalars(generic::spawn_origin(kScalar, lanes(p), lanes(p_error), lanes(n), lanes(dir))), dir, kInfinity};
}

Ray Surfel::spawn_to(const vec3& target, const vec3& target_error, const vec3& target_n) const {
  using namespace width1;
  F3 origin, dir;
  F dist;
  generic::spawn_to(kScalar, lanes(p), lanes(p_error), lanes(n), lanes(target), lanes(target_error), lanes(target_n),
                    origin, dir, dist);
  return Ray{scalars(origin), scalars(dir), dist.raw};
}

}  // namespace pathlab
