#include "core/bsdf/disney.h"

#include "core/bsdf/cospow.h"
#include "core/bsdf/disney_diffuse.h"
#include "core/bsdf/fresnel.h"
#include "core/bsdf/gtr1.h"
#include "core/bsdf/microfacet.h"
#include "core/bsdf/sheen.h"
#include "core/faults.h"
#include "core/sampling.h"

namespace pathlab::disney {

namespace {

constexpr float kClearcoatGAlpha = 0.25f;  // Burley's fixed masking roughness for the clearcoat

Spectrum specular_eval(const Closure& c, const vec3& wo, const vec3& wi, const vec3& h, float FH) {
  const microfacet::Ggx ggx{c.ax, c.ay};
  // G_s / (4 NL NV) * NL = g(wo) g(wi) NL (microfacet.h)
  const float gi = PATHLAB_FAULT(SmithG1Dropped) ? 0.5f / std::max(wi.z, 1e-20f) : ggx.g(wi);
  if (PATHLAB_FAULT(SpecularNoDenominator))
    return glm::mix(c.spec0, Spectrum(1.0f), FH) * (ggx.D(h) * ggx.G1(wo) * ggx.G1(wi) * wi.z);
  return glm::mix(c.spec0, Spectrum(1.0f), FH) * (ggx.D(h) * ggx.g(wo) * gi * wi.z);
}

float clearcoat_eval(const Closure& c, const vec3& wo, const vec3& wi, const vec3& h, float FH) {
  const float Fr = 0.04f + 0.96f * FH;
  return c.clearcoat * Fr * gtr1::D(h.z, c.clearcoat_alpha) * gtr1::g(wo.z, kClearcoatGAlpha) *
         gtr1::g(wi.z, kClearcoatGAlpha) * wi.z;
}

float specular_alpha(const Closure& c) { return std::sqrt(c.ax * c.ay); }

// Density of the specular family's sampler at wi (wo.z >= 0, wi.z > 0).
float specular_pdf(const Closure& c, const vec3& wo, const vec3& wi, BsdfSampling sampling) {
  if (sampling == BsdfSampling::Cospow)
    return cospow::pdf(microfacet::reflect(wo, vec3(0, 0, 1)), cospow::exponent_from_alpha(specular_alpha(c)), wi);
  const vec3 h = microfacet::half_vector(wo, wi);
  const microfacet::Ggx ggx{c.ax, c.ay};
  // G1(wo) D(h) (wo.h) / wo.z times the reflection Jacobian 1 / (4 wo.h).
  float p = 0.5f * ggx.g(wo) * ggx.D(h);
  if (PATHLAB_FAULT(VndfPdfWithoutJacobian)) p *= 4.0f * std::max(0.0f, glm::dot(wo, h));
  if (PATHLAB_FAULT(SpecularPdfOff5Percent)) p *= 1.05f;
  return p;
}

float clearcoat_pdf(const Closure& c, const vec3& wo, const vec3& wi, BsdfSampling sampling) {
  if (sampling == BsdfSampling::Cospow)
    return cospow::pdf(microfacet::reflect(wo, vec3(0, 0, 1)), cospow::exponent_from_alpha(c.clearcoat_alpha), wi);
  const vec3 h = microfacet::half_vector(wo, wi);
  const float wo_h = glm::dot(wo, h);
  // D(h) cos_h / (4 wo.h). The Jacobian 1 / (4 wo.h) is unbounded where h
  // turns perpendicular to wo (wi grazing back along -wo, reachable only
  // when wo itself grazes): below wo.h = 1e-20 report 0, a set of measure
  // zero, instead of an infinity (D <= 2.3e4, so the quotient stays below
  // 6e23 above the cut).
  return wo_h > 1e-20f ? gtr1::D(h.z, c.clearcoat_alpha) * h.z / (4.0f * wo_h) : 0.0f;
}

std::optional<vec3> specular_sample(const Closure& c, const vec3& wo, vec2 u, BsdfSampling sampling) {
  vec3 wi;
  if (sampling == BsdfSampling::Cospow) {
    wi = cospow::sample(microfacet::reflect(wo, vec3(0, 0, 1)), cospow::exponent_from_alpha(specular_alpha(c)), u);
  } else {
    const vec3 h = microfacet::Ggx{c.ax, c.ay}.sample_visible(wo, u);
    wi = microfacet::reflect(wo, h);
  }
  if (!(wi.z > 0.0f)) return std::nullopt;  // below the surface: no energy
  return glm::normalize(wi);
}

std::optional<vec3> clearcoat_sample(const Closure& c, const vec3& wo, vec2 u, BsdfSampling sampling) {
  vec3 wi;
  if (sampling == BsdfSampling::Cospow) {
    wi = cospow::sample(microfacet::reflect(wo, vec3(0, 0, 1)), cospow::exponent_from_alpha(c.clearcoat_alpha), u);
  } else {
    vec3 h = gtr1::sample(u, c.clearcoat_alpha);
    wi = microfacet::reflect(wo, h);
  }
  if (!(wi.z > 0.0f)) return std::nullopt;
  return glm::normalize(wi);
}

// Every term needs both directions strictly above the surface. A direction
// exactly in the surface (z = 0) or below carries no projected area.
bool above(const vec3& wo, const vec3& wi) {
  if (PATHLAB_FAULT(HorizonUnclamped)) return wo.z > 0.0f;
  return wo.z > 0.0f && wi.z > 0.0f;
}

}  // namespace

LobeProbabilities lobe_probabilities(const Closure& c, const vec3& wo, unsigned features, BsdfSampling sampling) {
  // Estimated energy of each family at this view angle: its colour's
  // luminance, Fresnel-weighted by Schlick at the view cosine. A lobe that
  // can reflect anything keeps at least 5 % of the samples, so that its pdf
  // is positive wherever its f is (Schlick makes a specular lobe with
  // F0 = 0 still reflect at grazing half-vector angles).
  const float Fw = fresnel::schlick_weight(wo.z);
  float e[3] = {0.0f, 0.0f, 0.0f};
  bool present[3] = {false, false, false};
  if (features & kLambertLobe) {
    e[0] += luminance(c.lambert);
    present[0] = present[0] || !is_black(c.lambert);
  }
  if (features & kDisneyLobes) {
    e[0] += luminance(c.diffuse) + luminance(c.sheen) * 0.1f;
    present[0] = present[0] || !is_black(c.diffuse) || !is_black(c.sheen);
    e[1] = c.specular * (luminance(c.spec0) * (1.0f - Fw) + Fw);
    present[1] = c.specular > 0.0f;
  }
  if (features & kClearcoat) {
    e[2] = c.clearcoat * (0.04f + 0.96f * Fw);
    present[2] = c.clearcoat > 0.0f;
  }
  if (c.energy.on) {  // what the layers above let through, seen from wo
    const float coat = (features & kClearcoat) ? c.energy.coat_transmit(wo.z) : 1.0f;
    e[0] *= coat * luminance(c.energy.diffuse_scale * c.energy.specular_transmit(wo.z));
    e[1] *= coat;
  }
  // Cospow: a cosine-power tail decays exponentially where GGX's decays as
  // a power, so f / pdf would be unbounded (it overflows at exponent 1e6).
  // The cosine lobe is always kept (at least the 5 % floor) as a defensive
  // component: then f cos / pdf <= f pi / 0.05, finite.
  if (sampling == BsdfSampling::Cospow && (features & kDisneyLobes)) present[0] = true;
  float total = 0.0f;
  for (int i = 0; i < 3; ++i) total += e[i];
  int n_present = 0;
  for (int i = 0; i < 3; ++i) n_present += present[i] ? 1 : 0;
  LobeProbabilities p{0.0f, 0.0f, 0.0f};
  if (n_present == 0) return p;
  float sum = 0.0f;
  for (int i = 0; i < 3; ++i) {
    if (!present[i]) continue;
    p[i] = std::max(total > 0.0f ? e[i] / total : 0.0f, 0.05f);
    sum += p[i];
  }
  for (float& x : p) x /= sum;
  return p;
}

template <unsigned F> Spectrum eval(const Closure& c, const vec3& wo, const vec3& wi) {
  if (!above(wo, wi)) return Spectrum(0.0f);
  const float NL = wi.z, NV = wo.z;
  Spectrum f(0.0f);
  if constexpr ((F & kLambertLobe) != 0) f += c.lambert * (NL * kInvPi);
  if constexpr ((F & (kDisneyLobes | kClearcoat)) != 0) {
    const vec3 h = microfacet::half_vector(wo, wi);
    const float LdotH = std::max(0.0f, glm::dot(wi, h));
    const float FH = fresnel::schlick_weight(LdotH);
    if constexpr ((F & kDisneyLobes) != 0) {
      Spectrum base = c.diffuse * disney_diffuse::eval_cos(c.roughness, c.subsurface, NL, NV, LdotH) +
                      c.sheen * sheen::eval_cos(NL, LdotH);
      if (c.energy.on && !PATHLAB_FAULT(DiffuseNotCoupled))
        base *= c.energy.diffuse_scale * c.energy.specular_transmit(NV) * c.energy.specular_transmit(NL);
      f += base + c.specular * specular_eval(c, wo, wi, h, FH);
    }
    if constexpr ((F & kClearcoat) != 0) {
      if (c.energy.on && !PATHLAB_FAULT(CoatNotCoupled)) f *= c.energy.coat_transmit(NV) * c.energy.coat_transmit(NL);
      f += Spectrum(clearcoat_eval(c, wo, wi, h, FH));
    }
  }
  return f;
}

template <unsigned F> float pdf(const Closure& c, const vec3& wo, const vec3& wi, BsdfSampling sampling) {
  if (!above(wo, wi)) return 0.0f;
  const LobeProbabilities p = lobe_probabilities(c, wo, F, sampling);
  float density = p[0] * cosine_hemisphere_pdf(wi);
  if constexpr ((F & kDisneyLobes) != 0) density += p[1] * specular_pdf(c, wo, wi, sampling);
  if constexpr ((F & kClearcoat) != 0) density += p[2] * clearcoat_pdf(c, wo, wi, sampling);
  return density;
}

template <unsigned F>
std::optional<DirectionSample> sample(const Closure& c, const vec3& wo, float u_lobe, vec2 u, BsdfSampling sampling) {
  if (!(wo.z > 0.0f)) return std::nullopt;
  const LobeProbabilities p = lobe_probabilities(c, wo, F, sampling);
  // u_lobe only chooses the family; the direction uses u.
  if (u_lobe < p[0]) {
    const vec3 wi = square_to_cosine_hemisphere(u);
    if (!(wi.z > 0.0f)) return std::nullopt;  // the disk's rim: grazing, no energy
    return DirectionSample{wi, is_black(c.lambert) ? Lobe::DisneyDiffuse : Lobe::Lambert};
  }
  if constexpr ((F & kDisneyLobes) != 0) {
    if (u_lobe < p[0] + p[1] || (F & kClearcoat) == 0 || !(p[2] > 0.0f)) {
      const auto wi = specular_sample(c, wo, u, sampling);
      if (!wi) return std::nullopt;
      return DirectionSample{*wi, Lobe::Specular};
    }
  }
  if constexpr ((F & kClearcoat) != 0) {
    if (p[2] > 0.0f) {
      const auto wi = clearcoat_sample(c, wo, u, sampling);
      if (!wi) return std::nullopt;
      return DirectionSample{*wi, Lobe::Clearcoat};
    }
  }
  return std::nullopt;
}

template Spectrum eval<kDisneyLobes>(const Closure&, const vec3&, const vec3&);
template Spectrum eval<kDisneyLobes | kClearcoat>(const Closure&, const vec3&, const vec3&);
template Spectrum eval<kGeneral>(const Closure&, const vec3&, const vec3&);
template float pdf<kDisneyLobes>(const Closure&, const vec3&, const vec3&, BsdfSampling);
template float pdf<kDisneyLobes | kClearcoat>(const Closure&, const vec3&, const vec3&, BsdfSampling);
template float pdf<kGeneral>(const Closure&, const vec3&, const vec3&, BsdfSampling);
template std::optional<DirectionSample> sample<kDisneyLobes>(const Closure&, const vec3&, float, vec2, BsdfSampling);
template std::optional<DirectionSample> sample<kDisneyLobes | kClearcoat>(const Closure&, const vec3&, float, vec2,
                                                                           BsdfSampling);
template std::optional<DirectionSample> sample<kGeneral>(const Closure&, const vec3&, float, vec2, BsdfSampling);

Spectrum lobe_eval(const Closure& c, SampledLobe lobe, const vec3& wo, const vec3& wi) {
  if (!above(wo, wi)) return Spectrum(0.0f);
  const vec3 h = microfacet::half_vector(wo, wi);
  const float LdotH = std::max(0.0f, glm::dot(wi, h));
  const float FH = fresnel::schlick_weight(LdotH);
  switch (lobe) {
    case SampledLobe::Diffuse:
      return c.lambert * (wi.z * kInvPi) + c.diffuse * disney_diffuse::eval_cos(c.roughness, c.subsurface, wi.z, wo.z, LdotH) +
             c.sheen * sheen::eval_cos(wi.z, LdotH);
    case SampledLobe::Specular: return c.specular * specular_eval(c, wo, wi, h, FH);
    case SampledLobe::Clearcoat: return Spectrum(clearcoat_eval(c, wo, wi, h, FH));
    case SampledLobe::Count: break;
  }
  return Spectrum(0.0f);
}

float lobe_pdf(const Closure& c, SampledLobe lobe, const vec3& wo, const vec3& wi, BsdfSampling sampling) {
  if (!above(wo, wi)) return 0.0f;
  switch (lobe) {
    case SampledLobe::Diffuse: return cosine_hemisphere_pdf(wi);
    case SampledLobe::Specular: return specular_pdf(c, wo, wi, sampling);
    case SampledLobe::Clearcoat: return clearcoat_pdf(c, wo, wi, sampling);
    case SampledLobe::Count: break;
  }
  return 0.0f;
}

std::optional<vec3> lobe_sample(const Closure& c, SampledLobe lobe, const vec3& wo, vec2 u, BsdfSampling sampling) {
  if (!(wo.z > 0.0f)) return std::nullopt;
  switch (lobe) {
    case SampledLobe::Diffuse: {
      const vec3 wi = square_to_cosine_hemisphere(u);
      return wi.z > 0.0f ? std::optional<vec3>(wi) : std::nullopt;
    }
    case SampledLobe::Specular: return specular_sample(c, wo, u, sampling);
    case SampledLobe::Clearcoat: return clearcoat_sample(c, wo, u, sampling);
    case SampledLobe::Count: break;
  }
  return std::nullopt;
}

}  // namespace pathlab::disney
