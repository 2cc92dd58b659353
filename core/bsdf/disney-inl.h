// Burley's principled BRDF (core/bsdf/disney.h says what it is) written once
// over Highway's vectors: core/bsdf/disney.cpp calls it at width 1 (core/
// simd/width1.h), for both tracers' scalar code, and the wavefront's
// vectorised stages at their SIMD width, for the flat untextured Disney
// materials they shade. Local shading frame, wo on the +z side; every
// function returns f cos(theta_i).
//
// What the callers choose:
//  - F, the lobes compiled in (disney::Features: "model only what a scene
//    requires");
//  - the glossy lobes' sampler: `Lobes` with specular_pdf/_sample and
//    clearcoat_pdf/_sample: VndfLobes below (exact visible normals, the
//    default) or CospowLobes (cosine-power lobes, cospow-inl.h);
//  - energy compensation (core/bsdf/energy.h): `Energy` (below) with the
//    layers' transmittances, from each lane's tables; NoEnergy for none;
//  - DisneyFaults: the test-only planted bugs core's fault build passes
//    (core/faults.h), all false elsewhere.
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_BSDF_DISNEY_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_BSDF_DISNEY_INL_H_
#undef PATHLAB_CORE_BSDF_DISNEY_INL_H_
#else
#define PATHLAB_CORE_BSDF_DISNEY_INL_H_
#endif

#include <hwy/highway.h>

#include "core/bsdf/cospow-inl.h"
#include "core/bsdf/energy.h"
#include "core/bsdf/microfacet-inl.h"
#include "core/math.h"
#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"
#include "core/simd/sampling-inl.h"

#ifndef PATHLAB_CORE_BSDF_DISNEY_INL_H_ONCE
#define PATHLAB_CORE_BSDF_DISNEY_INL_H_ONCE
namespace pathlab::disney {
// The planted bugs of core/faults.h that live in these formulas.
struct DisneyFaults {
  bool smith_g1_dropped = false;
  bool specular_no_denominator = false;
  bool vndf_pdf_without_jacobian = false;
  bool specular_pdf_off_5_percent = false;
  bool horizon_unclamped = false;
  bool diffuse_not_coupled = false;
  bool coat_not_coupled = false;
};
// Burley's fixed masking roughness for the clearcoat.
inline constexpr float kClearcoatGAlpha = 0.25f;
}  // namespace pathlab::disney
#endif

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// disney::Closure in lanes (core/bsdf/closure.h).
template <class V>
struct ClosureLanes {
  Vec3<V> lambert, diffuse;
  V roughness, subsurface;
  Vec3<V> sheen;
  V specular;
  Vec3<V> spec0;
  V ax, ay, clearcoat, clearcoat_alpha, clearcoat_log_a2, clearcoat_log2_a2;
};

// Rec. 709 luminance (core/math.h's luminance).
template <class D, class V = VecOf<D>>
HWY_INLINE V luminance(D d, const Vec3<V>& c) {
  return (Set(d, 0.2126f) * c.x + Set(d, 0.7152f) * c.y) + Set(d, 0.0722f) * c.z;
}

// Schlick's weight (1 - c)^5, with 1 - c clamped to [0, 1] (std::clamp's
// order): c is a dot product of unit vectors and can round a hair above 1.
template <class D, class V = VecOf<D>>
HWY_INLINE V schlick_weight(D d, V c) {
  const V zero = Zero(d), one = Set(d, 1.0f);
  const V v = one - c;
  const V m = IfThenElse(v < zero, zero, IfThenElse(one < v, one, v));
  const V m2 = m * m;
  return (m2 * m2) * m;
}

// Burley's diffuse with retro-reflection and the Hanrahan-Krueger-inspired
// subsurface approximation (Burley 2012 5.3, disney.brdf), f cos(theta_i)
// per unit base colour:
//   Fd   = (1 + (Fd90 - 1) FL)(1 + (Fd90 - 1) FV),    Fd90 = 0.5 + 2 roughness cos_d^2
//   Fss  = (1 + (Fss90 - 1) FL)(1 + (Fss90 - 1) FV),  Fss90 = roughness cos_d^2
//   ss   = 1.25 (Fss (1 / (NL + NV) - 0.5) + 0.5)
//   f    = mix(Fd, ss, subsurface) / pi
// with FL, FV Schlick weights of the light and view cosines and cos_d = L.H.
template <class D, class V = VecOf<D>>
HWY_INLINE V disney_diffuse_cos(D d, V roughness, V subsurface, V NL, V NV, V LdotH) {
  const V one = Set(d, 1.0f);
  const V FL = schlick_weight(d, NL), FV = schlick_weight(d, NV);
  const V cd2 = LdotH * LdotH;
  const V fd90 = Set(d, 0.5f) + (Set(d, 2.0f) * roughness) * cd2;
  const V fd = (one + (fd90 - one) * FL) * (one + (fd90 - one) * FV);
  const V fss90 = roughness * cd2;
  const V fss = (one + (fss90 - one) * FL) * (one + (fss90 - one) * FV);
  // ss NL with the 1 / (NL + NV) folded into NL / (NL + NV) <= 1: the plain
  // form overflows to infinity when both cosines are tiny (denormal).
  const V sum = NL + NV;
  const V q = IfThenElseZero(sum > Zero(d), NL / sum);
  const V half_nl = Set(d, 0.5f) * NL;
  const V ss_nl = Set(d, 1.25f) * (fss * (q - half_nl) + half_nl);
  return (fd * NL + (ss_nl - fd * NL) * subsurface) * Set(d, kInvPi);
}

// Burley's sheen (2012 5.3), a grazing retro-reflective tint for cloth:
// f = sheen Csheen FH with FH = (1 - L.H)^5 (no 1/pi, as published); per
// unit colour, times cos(theta_i).
template <class D, class V = VecOf<D>>
HWY_INLINE V sheen_cos(D d, V NL, V LdotH) {
  return schlick_weight(d, LdotH) * NL;
}

// The glossy lobes' densities and samplers by exact visible-normal sampling
// (BsdfSampling::Vndf). A sample's direction is normalised; `ok` false
// where it falls below the surface (it has f = 0: the pdf counts that mass
// as lost).
struct VndfLobes {
  // Whether the mixture keeps the cosine lobe whatever the material (disney.h: cospow's tails need it).
  static constexpr bool kKeepsCosine = false;
  template <class D, class V = VecOf<D>>
  HWY_INLINE V specular_pdf(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, const Vec3<V>& wi,
                            const disney::DisneyFaults& faults) const {
    const Vec3<V> h = half_vector(d, wo, wi);
    // G1(wo) D(h) (wo.h) / wo.z times the reflection Jacobian 1 / (4 wo.h).
    V p = (Set(d, 0.5f) * ggx_g(d, c.ax, c.ay, wo)) * ggx_D(d, c.ax, c.ay, h);
    if (faults.vndf_pdf_without_jacobian) p = p * (Set(d, 4.0f) * Max(dot(wo, h), Zero(d)));
    if (faults.specular_pdf_off_5_percent) p = p * Set(d, 1.05f);
    return p;
  }
  template <class D, class V = VecOf<D>>
  HWY_INLINE V clearcoat_pdf(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, const Vec3<V>& wi) const {
    const Vec3<V> h = half_vector(d, wo, wi);
    const V wo_h = dot(wo, h);
    // D(h) cos_h / (4 wo.h). The Jacobian 1 / (4 wo.h) is unbounded where h
    // turns perpendicular to wo (wi grazing back along -wo, reachable only
    // when wo itself grazes): below wo.h = 1e-20 report 0, a set of measure
    // zero, instead of an infinity (D <= 2.3e4, so the quotient stays below
    // 6e23 above the cut).
    const V value = (gtr1_D(d, h, c.clearcoat_alpha, c.clearcoat_log_a2) * h.z) / (Set(d, 4.0f) * wo_h);
    return IfThenElseZero(wo_h > Set(d, 1e-20f), value);
  }
  template <class D, class V = VecOf<D>>
  HWY_INLINE auto specular_sample(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, V ux, V uy, Vec3<V>& wi) const {
    wi = reflect(wo, ggx_sample_visible(d, c.ax, c.ay, wo, ux, uy));
    const auto ok = wi.z > Zero(d);
    wi = normalize(d, wi);
    return ok;
  }
  template <class D, class V = VecOf<D>>
  HWY_INLINE auto clearcoat_sample(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, V ux, V uy, Vec3<V>& wi) const {
    wi = reflect(wo, gtr1_sample(d, ux, uy, c.clearcoat_alpha, c.clearcoat_log2_a2));
    const auto ok = wi.z > Zero(d);
    wi = normalize(d, wi);
    return ok;
  }
};

// The glossy lobes' densities and samplers by cosine-power lobes about wo's
// mirror direction (BsdfSampling::Cospow, cospow-inl.h), of exponent
// 2 / alpha^2 - 2: the specular lobe's alpha is sqrt(ax ay), the clear
// coat's its own. A sample is normalised; `ok` false where it falls below
// the surface.
struct CospowLobes {
  // Whether the mixture keeps the cosine lobe whatever the material (disney.h: cospow's tails need it).
  static constexpr bool kKeepsCosine = true;
  template <class D, class V = VecOf<D>>
  HWY_INLINE V specular_pdf(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, const Vec3<V>& wi,
                            const disney::DisneyFaults&) const {
    return pdf(d, Sqrt(c.ax * c.ay), wo, wi);
  }
  template <class D, class V = VecOf<D>>
  HWY_INLINE V clearcoat_pdf(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, const Vec3<V>& wi) const {
    return pdf(d, c.clearcoat_alpha, wo, wi);
  }
  template <class D, class V = VecOf<D>>
  HWY_INLINE auto specular_sample(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, V ux, V uy, Vec3<V>& wi) const {
    return sample(d, Sqrt(c.ax * c.ay), wo, ux, uy, wi);
  }
  template <class D, class V = VecOf<D>>
  HWY_INLINE auto clearcoat_sample(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, V ux, V uy, Vec3<V>& wi) const {
    return sample(d, c.clearcoat_alpha, wo, ux, uy, wi);
  }
  // The lobe of roughness alpha about wo mirrored about the normal (0, 0, 1).
  template <class D, class V = VecOf<D>>
  static HWY_INLINE V pdf(D d, V alpha, const Vec3<V>& wo, const Vec3<V>& wi) {
    return cospow_pdf(d, Vec3<V>{Neg(wo.x), Neg(wo.y), wo.z}, cospow_exponent(d, alpha), wi);
  }
  template <class D, class V = VecOf<D>>
  static HWY_INLINE auto sample(D d, V alpha, const Vec3<V>& wo, V ux, V uy, Vec3<V>& wi) {
    wi = cospow_sample(d, Vec3<V>{Neg(wo.x), Neg(wo.y), wo.z}, cospow_exponent(d, alpha), ux, uy);
    return wi.z > Zero(d);
  }
};

// Energy compensation's layers (core/bsdf/energy.h), for the lanes whose
// material has its tables: where `on`, f and the lobe probabilities are
// coupled, elsewhere they are Burley's. An Energy has any() (some lane is
// on), on() (the mask), and the transmittances specular_transmit(d, mu),
// coat_transmit(d, mu) and diffuse_scale(d), looked up by the functions
// below from its tables. NoEnergy: none (its lookups are never called).
struct NoEnergy {
  static constexpr bool any() { return false; }
  template <class D>
  auto on(D d) const {
    return Zero(d) > Zero(d);
  }
  template <class D, class V = VecOf<D>>
  Vec3<V> specular_transmit(D d, V) const {
    return {Zero(d), Zero(d), Zero(d)};
  }
  template <class D, class V = VecOf<D>>
  V coat_transmit(D d, V) const {
    return Zero(d);
  }
  template <class D, class V = VecOf<D>>
  Vec3<V> diffuse_scale(D d) const {
    return {Zero(d), Zero(d), Zero(d)};
  }
};

// energy_table_position: view cosine mu's place in the tables, entry i (a
// whole number, as a float) and the weight w of entry i + 1; mu outside
// (0, 1] (NaN too) as its nearest end.
template <class D, class V = VecOf<D>>
HWY_INLINE V energy_table_position(D d, V mu, V& i) {
  const V m = IfThenElseZero(mu > Zero(d), Min(Set(d, 1.0f), mu));  // std::min(mu, 1)
  const V t = Sqrt(m) * Set(d, static_cast<float>(disney::kEnergyTableSize - 1));
  i = Min(Set(d, static_cast<float>(disney::kEnergyTableSize - 2)), Floor(t));  // t >= 0: the int conversion
  return t - i;
}

// EnergyTables::specular_transmit: 1 - the specular albedo at mu, per
// channel, clamped to [0, 1] (glm::clamp's order); `entry(i)` the table's
// entry i (a Vec3 of lanes).
template <class D, class Entry, class V = VecOf<D>>
HWY_INLINE Vec3<V> specular_transmit(D d, V mu, Entry&& entry) {
  V i;
  const V w = energy_table_position(d, mu, i);
  const Vec3<V> a = entry(i), b = entry(i + Set(d, 1.0f));
  const V keep = Set(d, 1.0f) - w;  // glm::mix(a, b, w) = a (1 - w) + b w
  const auto clamp = [&](V x) { return Min(Set(d, 1.0f), Max(Zero(d), Set(d, 1.0f) - x)); };
  return {clamp(a.x * keep + b.x * w), clamp(a.y * keep + b.y * w), clamp(a.z * keep + b.z * w)};
}

// EnergyTables::coat_transmit: 1 - the clearcoat's albedo at mu, clamped to
// [0, 1] (std::clamp's order); `entry(i)` the table's entry i.
template <class D, class Entry, class V = VecOf<D>>
HWY_INLINE V coat_transmit(D d, V mu, Entry&& entry) {
  V i;
  const V w = energy_table_position(d, mu, i);
  const V a = entry(i), b = entry(i + Set(d, 1.0f));
  const V x = Set(d, 1.0f) - (a + (b - a) * w);
  return IfThenElse(x < Zero(d), Zero(d), IfThenElse(Set(d, 1.0f) < x, Set(d, 1.0f), x));
}

// Both directions strictly above the surface: every term needs them (a
// direction exactly in the surface carries no projected area).
template <class D, class V = VecOf<D>>
HWY_INLINE auto disney_above(D d, const Vec3<V>& wo, const Vec3<V>& wi, const disney::DisneyFaults& faults) {
  if (faults.horizon_unclamped) return wo.z > Zero(d);
  return And(wo.z > Zero(d), wi.z > Zero(d));
}

// The probabilities of the sampled lobe families (diffuse, specular,
// clearcoat; disney::lobe_probabilities says how they are estimated), 0
// for a family that is absent.
template <unsigned F, class D, class Energy, class V = VecOf<D>>
HWY_INLINE void disney_lobe_probabilities(D d, const ClosureLanes<V>& c, V wo_z, bool cospow, const Energy& energy,
                                          V p[3]) {
  constexpr unsigned kDisneyLobes = 1u, kClearcoat = 2u, kLambertLobe = 4u;  // disney::Features
  const V zero = Zero(d), one = Set(d, 1.0f);
  const V Fw = schlick_weight(d, wo_z);
  V e[3] = {zero, zero, zero};
  auto present0 = zero > zero, present1 = present0, present2 = present0;
  if constexpr ((F & kLambertLobe) != 0) {
    e[0] = e[0] + luminance(d, c.lambert);
    present0 = Or(present0, Not(is_black(d, c.lambert)));
  }
  if constexpr ((F & kDisneyLobes) != 0) {
    e[0] = e[0] + (luminance(d, c.diffuse) + luminance(d, c.sheen) * Set(d, 0.1f));
    present0 = Or(present0, Or(Not(is_black(d, c.diffuse)), Not(is_black(d, c.sheen))));
    e[1] = c.specular * (luminance(d, c.spec0) * (one - Fw) + Fw);
    present1 = c.specular > zero;
  }
  if constexpr ((F & kClearcoat) != 0) {
    e[2] = c.clearcoat * (Set(d, 0.04f) + Set(d, 0.96f) * Fw);
    present2 = c.clearcoat > zero;
  }
  if (energy.any()) {  // what the layers above let through, seen from wo
    const auto on = energy.on(d);
    const V coat = (F & kClearcoat) != 0 ? energy.coat_transmit(d, wo_z) : one;
    e[0] = IfThenElse(on, e[0] * (coat * luminance(d, energy.diffuse_scale(d) * energy.specular_transmit(d, wo_z))), e[0]);
    e[1] = IfThenElse(on, e[1] * coat, e[1]);
  }
  // Cospow: the cosine lobe is always kept (disney.h).
  if (cospow && (F & kDisneyLobes) != 0) present0 = zero == zero;
  const V total = ((zero + e[0]) + e[1]) + e[2];
  const auto present_any = Or(Or(present0, present1), present2);
  const decltype(present0) present[3] = {present0, present1, present2};
  V sum = zero;
  for (int i = 0; i < 3; ++i) {
    // std::max(share, 0.05f) in Max's order; the absent add nothing (+0).
    p[i] = IfThenElseZero(present[i], Max(Set(d, 0.05f), IfThenElseZero(total > zero, e[i] / total)));
    sum = sum + p[i];
  }
  for (int i = 0; i < 3; ++i) p[i] = IfThenElseZero(present_any, p[i] / sum);
}

// The families' f cos(theta_i) for directions above the surface, as Burley
// defines them (uncoupled), given the half vector h and FH = Schlick's
// weight of wi.h: the diffuse family (Disney diffuse and sheen) ...
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> diffuse_family(D d, const ClosureLanes<V>& c, V NL, V NV, V LdotH) {
  return disney_diffuse_cos(d, c.roughness, c.subsurface, NL, NV, LdotH) * c.diffuse + sheen_cos(d, NL, LdotH) * c.sheen;
}

// ... the specular lobe, specular mix(Cspec0, 1, FH) D G_s / (4 NL NV) NL,
// with G_s / (4 NL NV) NL = g(wo) g(wi) NL (microfacet-inl.h) ...
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> specular_family(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, const Vec3<V>& wi, const Vec3<V>& h,
                                   V FH, const disney::DisneyFaults& faults) {
  const V gi = faults.smith_g1_dropped ? Set(d, 0.5f) / Max(Set(d, 1e-20f), wi.z) : ggx_g(d, c.ax, c.ay, wi);
  V lobe = ((ggx_D(d, c.ax, c.ay, h) * ggx_g(d, c.ax, c.ay, wo)) * gi) * wi.z;
  if (faults.specular_no_denominator) {
    const V g1o = (Set(d, 2.0f) * wo.z) * ggx_g(d, c.ax, c.ay, wo);
    const V g1i = (Set(d, 2.0f) * wi.z) * ggx_g(d, c.ax, c.ay, wi);
    lobe = ((ggx_D(d, c.ax, c.ay, h) * g1o) * g1i) * wi.z;
  }
  const V keep = Set(d, 1.0f) - FH;  // glm::mix(spec0, 1, FH) = spec0 (1 - FH) + 1 FH
  const Vec3<V> tint{c.spec0.x * keep + FH, c.spec0.y * keep + FH, c.spec0.z * keep + FH};
  return c.specular * (lobe * tint);
}

// ... and the clearcoat, 0.25 clearcoat F_r D_GTR1 G_r / (4 NL NV) NL with
// F_r = mix(0.04, 1, FH) and Burley's fixed masking roughness.
template <class D, class V = VecOf<D>>
HWY_INLINE V clearcoat_family(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, const Vec3<V>& wi, const Vec3<V>& h,
                              V FH) {
  const V a = Set(d, disney::kClearcoatGAlpha);
  const V Fr = Set(d, 0.04f) + Set(d, 0.96f) * FH;
  return ((((c.clearcoat * Fr) * gtr1_D(d, h, c.clearcoat_alpha, c.clearcoat_log_a2)) * gtr1_g(d, wo.z, a)) *
          gtr1_g(d, wi.z, a)) *
         wi.z;
}

// f cos(theta_i) of the lobes of F; 0 unless wo and wi are above.
template <unsigned F, class D, class Energy, class V = VecOf<D>>
HWY_INLINE Vec3<V> disney_eval(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, const Vec3<V>& wi,
                               const Energy& energy, const disney::DisneyFaults& faults) {
  constexpr unsigned kDisneyLobes = 1u, kClearcoat = 2u, kLambertLobe = 4u;
  const V zero = Zero(d);
  const auto above = disney_above(d, wo, wi, faults);
  if (AllFalse(d, above)) return {zero, zero, zero};  // nothing to compute (every light sample below, at width 1)
  const V NL = wi.z, NV = wo.z;
  Vec3<V> f{zero, zero, zero};
  if constexpr ((F & kLambertLobe) != 0) f = f + (NL * Set(d, kInvPi)) * c.lambert;
  if constexpr ((F & (kDisneyLobes | kClearcoat)) != 0) {
    const Vec3<V> h = half_vector(d, wo, wi);
    const V LdotH = Max(dot(wi, h), zero);
    const V FH = schlick_weight(d, LdotH);
    if constexpr ((F & kDisneyLobes) != 0) {
      Vec3<V> base = diffuse_family(d, c, NL, NV, LdotH);
      if (energy.any() && !faults.diffuse_not_coupled)
        base = select(energy.on(d),
                      base * ((energy.diffuse_scale(d) * energy.specular_transmit(d, NV)) * energy.specular_transmit(d, NL)),
                      base);
      f = f + (base + specular_family(d, c, wo, wi, h, FH, faults));
    }
    if constexpr ((F & kClearcoat) != 0) {
      if (energy.any() && !faults.coat_not_coupled)
        f = select(energy.on(d), (energy.coat_transmit(d, NV) * energy.coat_transmit(d, NL)) * f, f);
      const V coat = clearcoat_family(d, c, wo, wi, h, FH);
      f = f + Vec3<V>{coat, coat, coat};
    }
  }
  return zero_unless(above, f);
}

// The solid-angle density of disney_sample at wi.
template <unsigned F, class D, class Lobes, class Energy, class V = VecOf<D>>
HWY_INLINE V disney_pdf(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, const Vec3<V>& wi, const Lobes& lobes,
                        const Energy& energy, const disney::DisneyFaults& faults) {
  constexpr unsigned kDisneyLobes = 1u, kClearcoat = 2u;
  const auto above = disney_above(d, wo, wi, faults);
  if (AllFalse(d, above)) return Zero(d);
  V p[3];
  disney_lobe_probabilities<F>(d, c, wo.z, Lobes::kKeepsCosine, energy, p);
  V density = p[0] * cosine_hemisphere_pdf(d, wi.z);
  if constexpr ((F & kDisneyLobes) != 0) density = density + p[1] * lobes.specular_pdf(d, c, wo, wi, faults);
  if constexpr ((F & kClearcoat) != 0) density = density + p[2] * lobes.clearcoat_pdf(d, c, wo, wi);
  return IfThenElseZero(above, density);
}

// A direction from the mixture for the lanes of the returned mask: u_lobe
// chooses the family (`family`: 0 diffuse, 1 specular, 2 clearcoat), (ux,
// uy) the direction. False where wo is not above, or the drawn direction
// falls at or below the surface (it has f = 0; the pdf counts that mass as
// lost).
template <unsigned F, class D, class Lobes, class Energy, class V = VecOf<D>>
HWY_INLINE auto disney_sample(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, V u_lobe, V ux, V uy,
                              const Lobes& lobes, const Energy& energy, Vec3<V>& wi, V& family) {
  constexpr unsigned kDisneyLobes = 1u, kClearcoat = 2u;
  const V zero = Zero(d);
  V p[3];
  disney_lobe_probabilities<F>(d, c, wo.z, Lobes::kKeepsCosine, energy, p);
  const auto up = wo.z > zero;
  const auto diffuse = And(up, u_lobe < p[0]);
  auto specular = zero > zero, coat = specular;
  if constexpr ((F & kDisneyLobes) != 0) {
    auto take = u_lobe < p[0] + p[1];
    if constexpr ((F & kClearcoat) == 0) take = zero == zero;
    else take = Or(take, Not(p[2] > zero));
    specular = And(And(up, Not(diffuse)), take);
  }
  if constexpr ((F & kClearcoat) != 0) coat = And(And(And(up, Not(diffuse)), Not(specular)), p[2] > zero);
  // Each family's direction where some lane draws from it: draw(lanes,
  // sampler), sampler(w) giving the lanes whose w is above the surface.
  wi = {zero, zero, zero};
  auto ok = zero > zero;
  const auto draw = [&](auto lanes, auto&& sampler) {
    if (AllFalse(d, lanes)) return;
    Vec3<V> w;
    const auto above = sampler(w);
    wi = select(lanes, w, wi);
    ok = Or(ok, And(lanes, above));
  };
  draw(diffuse, [&](Vec3<V>& w) {
    cosine_hemisphere(d, ux, uy, w.x, w.y, w.z);
    return w.z > zero;  // the disk's rim: grazing, no energy
  });
  if constexpr ((F & kDisneyLobes) != 0)
    draw(specular, [&](Vec3<V>& w) { return lobes.specular_sample(d, c, wo, ux, uy, w); });
  if constexpr ((F & kClearcoat) != 0)
    draw(coat, [&](Vec3<V>& w) { return lobes.clearcoat_sample(d, c, wo, ux, uy, w); });
  family = IfThenElse(specular, Set(d, 1.0f), IfThenElseZero(coat, Set(d, 2.0f)));
  return ok;
}

// Surfel::scatter's draw from a Disney closure, wo on +z (disney::scatter,
// which core/surfel.cpp calls; the wavefront's scatter stage): a direction
// from the mixture (disney_sample, `family` its lobe family), weighted by
// f cos over the mixture's density there, whatever family drew it. False
// where nothing was drawn or the density is unusable (usable_bsdf_pdf).
template <unsigned F, class D, class Lobes, class Energy, class V = VecOf<D>>
HWY_INLINE auto disney_scatter(D d, const ClosureLanes<V>& c, const Vec3<V>& wo, V u_lobe, V ux, V uy,
                               const Lobes& lobes, const Energy& energy, V min_pdf,
                               const disney::DisneyFaults& faults, Vec3<V>& wi, Vec3<V>& weight, V& pdf, V& family) {
  auto drawn = disney_sample<F>(d, c, wo, u_lobe, ux, uy, lobes, energy, wi, family);
  weight = {Zero(d), Zero(d), Zero(d)};
  pdf = Zero(d);
  if (AllFalse(d, drawn)) return drawn;
  pdf = disney_pdf<F>(d, c, wo, wi, lobes, energy, faults);
  drawn = And(drawn, usable_bsdf_pdf(d, pdf, min_pdf));
  if (AllFalse(d, drawn)) return drawn;
  weight = disney_eval<F>(d, c, wo, wi, energy, faults) / pdf;
  return drawn;
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_BSDF_DISNEY_INL_H_ toggle
