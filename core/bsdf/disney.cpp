#include "core/bsdf/disney.h"

#include "core/bsdf/cospow.h"
#include "core/bsdf/disney-inl.h"
#include "core/bsdf/microfacet.h"
#include "core/faults.h"
#include "core/sampling.h"
#include "core/simd/width1.h"

namespace pathlab {

float cospow::exponent_from_alpha(float alpha) {
  return width1::generic::cospow_exponent(width1::kScalar, width1::F{alpha}).raw;
}

namespace disney {

namespace {

using namespace width1;
using generic::ClosureLanes;

ClosureLanes<F> lanes_of(const Closure& c) {
  return {lanes(c.lambert), lanes(c.diffuse), F{c.roughness}, F{c.subsurface}, lanes(c.sheen), F{c.specular},
          lanes(c.spec0), F{c.ax}, F{c.ay}, F{c.clearcoat}, F{c.clearcoat_alpha}, F{c.clearcoat_log_a2},
          F{c.clearcoat_log2_a2}};
}

// The closure's energy tables (energy.h) as disney-inl.h's Energy reads them.
struct TableEnergy {
  const EnergyTables& tables;
  bool any() const { return tables.on; }
  lane1::M on(lane1::One<float>) const { return {tables.on}; }
  F3 specular_transmit(lane1::One<float>, F mu) const { return lanes(tables.specular_transmit(mu.raw)); }
  F coat_transmit(lane1::One<float>, F mu) const { return F{tables.coat_transmit(mu.raw)}; }
  F3 diffuse_scale(lane1::One<float>) const { return lanes(tables.diffuse_scale); }
};

// The planted bugs of these formulas (core/faults.h; all false but in the
// fault build's tests).
DisneyFaults faults() {
  return {PATHLAB_FAULT(SmithG1Dropped),         PATHLAB_FAULT(SpecularNoDenominator), PATHLAB_FAULT(VndfPdfWithoutJacobian),
          PATHLAB_FAULT(SpecularPdfOff5Percent), PATHLAB_FAULT(HorizonUnclamped),      PATHLAB_FAULT(DiffuseNotCoupled),
          PATHLAB_FAULT(CoatNotCoupled)};
}

// The mixture under the closure's sampling: fn(lobes).
template <class Fn>
auto with_lobes(BsdfSampling sampling, Fn&& fn) {
  if (sampling == BsdfSampling::Cospow) return fn(generic::CospowLobes{});
  return fn(generic::VndfLobes{});
}

std::optional<vec3> family_sample(const Closure& c, SampledLobe lobe, const vec3& wo, vec2 u, BsdfSampling sampling) {
  return with_lobes(sampling, [&](const auto& lobes) -> std::optional<vec3> {
    F3 wi;
    const ClosureLanes<F> cl = lanes_of(c);
    const lane1::M ok = lobe == SampledLobe::Specular ? lobes.specular_sample(kScalar, cl, lanes(wo), F{u.x}, F{u.y}, wi)
                                                      : lobes.clearcoat_sample(kScalar, cl, lanes(wo), F{u.x}, F{u.y}, wi);
    if (!ok.raw) return std::nullopt;
    return scalars(wi);
  });
}

// The Lobe a sample of disney_sample's `family` reports (0 diffuse: the
// Lambert lobe where the closure has one, 1 specular, 2 clearcoat).
Lobe lobe_of(const Closure& c, F family) {
  return family.raw == 1.0f   ? Lobe::Specular
         : family.raw == 2.0f ? Lobe::Clearcoat
         : is_black(c.lambert) ? Lobe::DisneyDiffuse
                               : Lobe::Lambert;
}

// Both directions above the surface (disney-inl.h's disney_above).
bool above(const vec3& wo, const vec3& wi) { return generic::disney_above(kScalar, lanes(wo), lanes(wi), faults()).raw; }

}  // namespace

LobeProbabilities lobe_probabilities(const Closure& c, const vec3& wo, unsigned features, BsdfSampling sampling) {
  F p[3] = {};
  const ClosureLanes<F> cl = lanes_of(c);
  const TableEnergy energy{c.energy};
  const bool cospow = sampling == BsdfSampling::Cospow;
  // Every feature set (disney::Features) to its instantiation.
  const auto at = [&]<unsigned Fs>() { generic::disney_lobe_probabilities<Fs>(kScalar, cl, F{wo.z}, cospow, energy, p); };
  switch (features & kGeneral) {
    case 0: at.operator()<0>(); break;
    case 1: at.operator()<1>(); break;
    case 2: at.operator()<2>(); break;
    case 3: at.operator()<3>(); break;
    case 4: at.operator()<4>(); break;
    case 5: at.operator()<5>(); break;
    case 6: at.operator()<6>(); break;
    default: at.operator()<7>(); break;
  }
  return {p[0].raw, p[1].raw, p[2].raw};
}

template <unsigned Fs> Spectrum eval(const Closure& c, const vec3& wo, const vec3& wi) {
  return scalars(generic::disney_eval<Fs>(kScalar, lanes_of(c), lanes(wo), lanes(wi), TableEnergy{c.energy}, faults()));
}

template <unsigned Fs> float pdf(const Closure& c, const vec3& wo, const vec3& wi, BsdfSampling sampling) {
  return with_lobes(sampling, [&](const auto& lobes) {
    return generic::disney_pdf<Fs>(kScalar, lanes_of(c), lanes(wo), lanes(wi), lobes, TableEnergy{c.energy},
                                   faults())
        .raw;
  });
}

template <unsigned Fs>
std::optional<DirectionSample> sample(const Closure& c, const vec3& wo, float u_lobe, vec2 u, BsdfSampling sampling) {
  return with_lobes(sampling, [&](const auto& lobes) -> std::optional<DirectionSample> {
    F3 wi;
    F family;
    if (!generic::disney_sample<Fs>(kScalar, lanes_of(c), lanes(wo), F{u_lobe}, F{u.x}, F{u.y}, lobes,
                                    TableEnergy{c.energy}, wi, family)
             .raw)
      return std::nullopt;
    return DirectionSample{scalars(wi), lobe_of(c, family)};
  });
}

template <unsigned Fs>
std::optional<Scatter> scatter(const Closure& c, const vec3& wo, float u_lobe, vec2 u, BsdfSampling sampling,
                               float min_pdf) {
  return with_lobes(sampling, [&](const auto& lobes) -> std::optional<Scatter> {
    F3 wi, weight;
    F pdf, family;
    if (!generic::disney_scatter<Fs>(kScalar, lanes_of(c), lanes(wo), F{u_lobe}, F{u.x}, F{u.y}, lobes,
                                     TableEnergy{c.energy}, F{min_pdf}, faults(), wi, weight, pdf, family)
             .raw)
      return std::nullopt;
    return Scatter{scalars(wi), scalars(weight), pdf.raw, lobe_of(c, family)};
  });
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
template std::optional<Scatter> scatter<kDisneyLobes>(const Closure&, const vec3&, float, vec2, BsdfSampling, float);
template std::optional<Scatter> scatter<kDisneyLobes | kClearcoat>(const Closure&, const vec3&, float, vec2,
                                                                   BsdfSampling, float);
template std::optional<Scatter> scatter<kGeneral>(const Closure&, const vec3&, float, vec2, BsdfSampling, float);

Spectrum lobe_eval(const Closure& c, SampledLobe lobe, const vec3& wo, const vec3& wi) {
  if (!above(wo, wi)) return Spectrum(0.0f);
  const ClosureLanes<F> cl = lanes_of(c);
  const F3 o = lanes(wo), i = lanes(wi);
  const F3 h = generic::half_vector(kScalar, o, i);
  const F LdotH = Max(generic::dot(i, h), F{0.0f});
  const F FH = generic::schlick_weight(kScalar, LdotH);
  switch (lobe) {
    case SampledLobe::Diffuse:
      return c.lambert * (wi.z * kInvPi) +
             c.diffuse * generic::disney_diffuse_cos(kScalar, cl.roughness, cl.subsurface, i.z, o.z, LdotH).raw +
             c.sheen * generic::sheen_cos(kScalar, i.z, LdotH).raw;
    case SampledLobe::Specular: return scalars(generic::specular_family(kScalar, cl, o, i, h, FH, faults()));
    case SampledLobe::Clearcoat: return Spectrum(generic::clearcoat_family(kScalar, cl, o, i, h, FH).raw);
    case SampledLobe::Count: break;
  }
  return Spectrum(0.0f);
}

float lobe_pdf(const Closure& c, SampledLobe lobe, const vec3& wo, const vec3& wi, BsdfSampling sampling) {
  if (!above(wo, wi)) return 0.0f;
  return with_lobes(sampling, [&](const auto& lobes) {
    const ClosureLanes<F> cl = lanes_of(c);
    switch (lobe) {
      case SampledLobe::Diffuse: return cosine_hemisphere_pdf(wi);
      case SampledLobe::Specular: return lobes.specular_pdf(kScalar, cl, lanes(wo), lanes(wi), faults()).raw;
      case SampledLobe::Clearcoat: return lobes.clearcoat_pdf(kScalar, cl, lanes(wo), lanes(wi)).raw;
      case SampledLobe::Count: break;
    }
    return 0.0f;
  });
}

std::optional<vec3> lobe_sample(const Closure& c, SampledLobe lobe, const vec3& wo, vec2 u, BsdfSampling sampling) {
  if (!(wo.z > 0.0f)) return std::nullopt;
  switch (lobe) {
    case SampledLobe::Diffuse: {
      const vec3 wi = square_to_cosine_hemisphere(u);
      return wi.z > 0.0f ? std::optional<vec3>(wi) : std::nullopt;
    }
    case SampledLobe::Specular:
    case SampledLobe::Clearcoat: return family_sample(c, lobe, wo, u, sampling);
    case SampledLobe::Count: break;
  }
  return std::nullopt;
}

}  // namespace disney
}  // namespace pathlab
