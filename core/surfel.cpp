#include "core/surfel.h"

#include "core/bsdf/lambert.h"
#include "core/bsdf/mirror.h"
#include "core/faults.h"

namespace pathlab {
namespace {

// The BSDFs are two-sided: flip the local frame so that wo is on +z.
struct LocalDirs {
  vec3 wo, wi;
};
LocalDirs to_local_upper(const Frame& frame, const vec3& wo, const vec3& wi) {
  LocalDirs d{frame.to_local(wo), frame.to_local(wi)};
  if (d.wo.z < 0.0f) {
    d.wo.z = -d.wo.z;
    d.wi.z = -d.wi.z;
  }
  return d;
}

}  // namespace

Spectrum Surfel::emitted(const vec3& wo) const {
  if (!material->emits()) return Spectrum(0.0f);
  if (material->two_sided_emission || glm::dot(n, wo) > 0.0f) return material->emission;
  return Spectrum(0.0f);
}

Spectrum Surfel::eval(const vec3& wi, const vec3& wo) const {
  if (material->type != MaterialType::Diffuse) return Spectrum(0.0f);
  const LocalDirs d = to_local_upper(frame, wo, wi);
  if (PATHLAB_FAULT(CosineDropped)) return d.wi.z > 0.0f ? material->albedo * kInvPi : Spectrum(0.0f);
  return lambert::eval(material->albedo, d.wi);
}

float Surfel::pdf(const vec3& wi, const vec3& wo) const {
  if (material->type != MaterialType::Diffuse) return 0.0f;
  const LocalDirs d = to_local_upper(frame, wo, wi);
  if (PATHLAB_FAULT(BsdfPdfOff5Percent)) return 1.05f * lambert::pdf(d.wi);
  return lambert::pdf(d.wi);
}

std::optional<BsdfSample> Surfel::scatter(const vec3& wo, float u_lobe, vec2 u) const {
  vec3 wo_local = frame.to_local(wo);
  const float side = wo_local.z < 0.0f ? -1.0f : 1.0f;
  wo_local.z *= side;
  switch (material->type) {
    case MaterialType::Diffuse: {
      vec3 wi = lambert::sample(u);
      const float pdf = lambert::pdf(wi);
      if (pdf <= 0.0f) return std::nullopt;  // u on the disk's rim: grazing, no energy
      wi.z *= side;
      if (PATHLAB_FAULT(BsdfPdfOff5Percent) || PATHLAB_FAULT(CosineDropped)) {
        const vec3 w = frame.to_world(wi);
        const float faulty_pdf = this->pdf(w, wo);
        return BsdfSample{w, eval(w, wo) / faulty_pdf, faulty_pdf, Lobe::Lambert, false};
      }
      return BsdfSample{frame.to_world(wi), material->albedo, pdf, Lobe::Lambert, false};
    }
    case MaterialType::Mirror: {
      // The impulse is chosen with probability equal to its mean reflectance
      // (absorbed otherwise), so its weight stays near 1 and paths end in
      // proportion to the energy they would lose.
      const float prob = std::min(1.0f, average(material->albedo));
      if (!(u_lobe < prob)) return std::nullopt;
      vec3 wi = mirror::reflect_local(wo_local);
      wi.z *= side;
      return BsdfSample{frame.to_world(wi), material->albedo / prob, prob, Lobe::MirrorImpulse, true};
    }
    case MaterialType::Emissive: return std::nullopt;
  }
  return std::nullopt;
}

std::optional<BsdfSample> Surfel::scatter_cosine(const vec3& wo, vec2 u) const {
  if (material->is_pure_impulse()) return std::nullopt;
  const float side = glm::dot(wo, n) < 0.0f ? -1.0f : 1.0f;
  vec3 wi_local = square_to_cosine_hemisphere(u);
  const float pdf = cosine_hemisphere_pdf(wi_local);
  if (pdf <= 0.0f) return std::nullopt;
  wi_local.z *= side;
  const vec3 wi = frame.to_world(wi_local);
  return BsdfSample{wi, eval(wi, wo) / pdf, pdf, Lobe::Lambert, false};
}

Ray Surfel::spawn(const vec3& dir) const {
  const vec3 side = glm::dot(dir, n) >= 0.0f ? n : -n;
  return Ray{offset_ray_origin(p, p_error, side), dir, kInfinity};
}

Ray Surfel::spawn_to(const vec3& target, const vec3& target_error, const vec3& target_n) const {
  const vec3 d0 = target - p;
  const vec3 origin = offset_ray_origin(p, p_error, glm::dot(d0, n) >= 0.0f ? n : -n);
  const vec3 end = offset_ray_origin(target, target_error,
                                     glm::dot(origin - target, target_n) >= 0.0f ? target_n : -target_n);
  const vec3 d = end - origin;
  const float dist = glm::length(d);
  // Both ends are strictly off their surfaces, so the full length is safe;
  // any shorter would let light through an occluder next to the target.
  return Ray{origin, d / dist, dist};
}

}  // namespace pathlab
