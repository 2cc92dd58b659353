// The microfacet distributions of the Disney model written once over
// Highway's vectors: core/bsdf/microfacet.h and gtr1.h call them at width 1
// (core/simd/width1.h), for both tracers' scalar code, and the wavefront's
// vectorised stages at their SIMD width. Local frame: z = the normal, x/y =
// the tangent directions of alpha_x/y.
//
// GGX, anisotropic (GTR2 with gamma = 2, Burley 2012 B.2), with separable
// Smith masking-shadowing and exact sampling of its visible normals (Heitz
// 2018, "Sampling the GGX Distribution of Visible Normals"):
//   D(h)      = 1 / (pi ax ay (hx^2/ax^2 + hy^2/ay^2 + hz^2)^2)
//   g(w)      = 1 / (wz + sqrt(ax^2 wx^2 + ay^2 wy^2 + wz^2)) = G1(w) / (2 wz)
//               (Burley's smithG_GGX_aniso; finite at wz = 0)
//   G1(w)     = 2 wz g(w)
//   VNDF pdf of the reflected wi:  G1(wo) D(h) / (4 wo.z) = g(wo) D(h) / 2
// GTR1 ("Berry"), the clearcoat's, isotropic, gamma = 1, sampled in
// proportion to D(h) cos(theta_h):
//   D(cos_h) = (a^2 - 1) / (pi ln(a^2) (1 + (a^2 - 1) cos_h^2))
// with ln(a^2) given (Closure::clearcoat_log_a2: a per-material constant,
// libm's, so that the lanes need no logarithm of their own).
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_BSDF_MICROFACET_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_BSDF_MICROFACET_INL_H_
#undef PATHLAB_CORE_BSDF_MICROFACET_INL_H_
#else
#define PATHLAB_CORE_BSDF_MICROFACET_INL_H_
#endif

#include <hwy/highway.h>

#include "core/math.h"
#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"
#include "core/simd/sampling-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// The mirror reflection of wo about the unit normal h: 2 (wo.h) h - wo.
template <class V>
HWY_INLINE Vec3<V> reflect(const Vec3<V>& wo, const Vec3<V>& h) {
  const V s = dot(wo, h);
  const V t = s + s;  // 2 (wo.h): doubling is exact
  return t * h - wo;
}

// The half vector of two directions on the same side (z > 0); the zero
// vector if they are opposite (then nothing reflects one into the other).
// Computed in double from the exactly normalised directions. At a grazing
// view (wo.z = 1e-3) the reflected lobe's wi is nearly -wo, and h's tilt
// comes from the difference of their near-unit horizontal components,
// about (wi.z^2 - wo.z^2) / 2 ~ 1e-6. A float direction's length is 1 only
// to ~6e-8, which alone moved that tilt by 1 % of alpha = 1e-3 and 1.6 % of
// the lobe's mass from one chi-square bin to another (test_bsdf_stat.cpp,
// BsdfChi2.FullMaterialAtGrazingView); the sampler (VNDF, reflect) is
// invariant to |wo| and was right.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> half_vector(D d, const Vec3<V>& wo, const Vec3<V>& wi) {
  return InDouble3(
      d,
      [](auto dd, const auto& a, const auto& b) {
        using VD = VecOf<decltype(dd)>;
        const VD zero = Zero(dd);
        const VD la = dot(a, a), lb = dot(b, b);
        const VD ra = Sqrt(la), rb = Sqrt(lb);
        const Vec3<VD> h = Vec3<VD>{a.x / ra, a.y / ra, a.z / ra} + Vec3<VD>{b.x / rb, b.y / rb, b.z / rb};
        const VD len2 = dot(h, h);
        const VD r = Sqrt(len2);
        const auto ok = And(And(la > zero, lb > zero), len2 > zero);
        return Vec3<VD>{IfThenElseZero(ok, h.x / r), IfThenElseZero(ok, h.y / r), IfThenElseZero(ok, h.z / r)};
      },
      wo, wi);
}

// GGX's D(h): 0 for h at or below the horizon.
template <class D, class V = VecOf<D>>
HWY_INLINE V ggx_D(D d, V ax, V ay, const Vec3<V>& h) {
  const V sx = h.x / ax, sy = h.y / ay;
  const V e = (sx * sx + sy * sy) + h.z * h.z;
  // e >= hz^2 > 0 here unless hz underflows; e is at most ~1e6 (1/alpha^2),
  // so e^2 cannot overflow.
  const V value = Set(d, 1.0f) / ((((Set(d, kPi) * ax) * ay) * e) * e);
  return IfThenElseZero(And(Not(h.z <= Zero(d)), e > Zero(d)), value);
}

// GGX's g(w) = G1(w) / (2 wz): 0 below the surface (wz < 0: masked).
template <class D, class V = VecOf<D>>
HWY_INLINE V ggx_g(D d, V ax, V ay, const Vec3<V>& w) {
  const V x = ax * w.x, y = ay * w.y;
  // s >= min(alpha) |w| > 0 for a unit w, so the division is safe.
  const V s = Sqrt((x * x + y * y) + w.z * w.z);
  return IfThenZeroElse(w.z < Zero(d), Set(d, 1.0f) / (w.z + s));
}

// A visible normal of GGX for wo (wo.z >= 0), from two uniform numbers.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> ggx_sample_visible(D d, V ax, V ay, const Vec3<V>& wo, V ux, V uy) {
  const V zero = Zero(d), one = Set(d, 1.0f);
  // Stretch the view to the hemisphere configuration.
  const Vec3<V> vh = normalize(d, Vec3<V>{ax * wo.x, ay * wo.y, wo.z});
  const V lensq = vh.x * vh.x + vh.y * vh.y;
  const V len = Sqrt(lensq);
  const auto tilted = lensq > zero;
  const Vec3<V> t1{IfThenElse(tilted, Neg(vh.y) / len, one), IfThenElseZero(tilted, vh.x / len),
                   IfThenElseZero(tilted, zero / len)};
  // glm::cross(vh, t1).
  const Vec3<V> t2{vh.y * t1.z - t1.y * vh.z, vh.z * t1.x - t1.z * vh.x, vh.x * t1.y - t1.x * vh.y};
  // A point on the projected disk, warped onto the visible half.
  const V r = Sqrt(ux);
  V sin_phi, cos_phi;
  sin_cos_turn(d, uy, sin_phi, cos_phi);
  const V p1 = r * cos_phi;
  const V s = Set(d, 0.5f) * (one + vh.z);
  // 1 - p1^2 can round below 0 when r rounds to 1: clamp (Max(v, 0) is
  // std::max(0, v), NaN included).
  const V p2 = (one - s) * Sqrt(Max(one - p1 * p1, zero)) + s * (r * sin_phi);
  const V lift = Sqrt(Max((one - p1 * p1) - p2 * p2, zero));
  const Vec3<V> nh = (p1 * t1 + p2 * t2) + lift * vh;
  // Unstretch; z >= 0 by construction, clamp the rounding.
  return normalize(d, Vec3<V>{ax * nh.x, ay * nh.y, Max(nh.z, zero)});
}

// GTR1's D for a half vector of cosine cos_h and squared sine sin2_h (both
// given: see below), with log_a2 = ln(a^2): 0 at or below the horizon.
template <class D, class V = VecOf<D>>
HWY_INLINE V gtr1_D(D d, V cos_h, V sin2_h, V a, V log_a2) {
  const V one = Set(d, 1.0f);
  const V a2 = a * a;  // a in [0.001, 0.1] (gloss in [0, 1]): a2 < 1, ln(a2) < 0
  // 1 + (a2 - 1) cos^2 written as a2 cos^2 + sin^2: at the peak (cos -> 1)
  // the published form cancels 1 against 1 - a2 and keeps only the float
  // rounding of a2 - 1 (6e-8, 6 % of a2 = 1e-6 at gloss 1: D was 1.3 %
  // low there). sin^2 is taken from the half vector's x and y, not as
  // (1 - cos)(1 + cos): floats below 1 are 6e-8 apart, so that form moves
  // in steps of 1.2e-7, 12 % of a2 at gloss 1, and D was a staircase
  // across the peak (its quadrature then missed 4e-4 of the lobe).
  const V denom = (a2 * cos_h) * cos_h + sin2_h;
  return IfThenZeroElse(cos_h <= Zero(d), (a2 - one) / ((Set(d, kPi) * log_a2) * denom));
}

// ... at the half vector h (unit, local frame).
template <class D, class V = VecOf<D>>
HWY_INLINE V gtr1_D(D d, const Vec3<V>& h, V a, V log_a2) {
  return gtr1_D(d, h.z, h.x * h.x + h.y * h.y, a, log_a2);
}

// Burley's smithG_GGX(c, a) / (2 c): 1 / (c + sqrt(a^2 + c^2 - a^2 c^2)),
// finite at c = 0, 0 below (c < 0).
template <class D, class V = VecOf<D>>
HWY_INLINE V gtr1_g(D d, V c, V a) {
  const V a2 = a * a;
  return IfThenZeroElse(c < Zero(d), Set(d, 1.0f) / (c + Sqrt((a2 + c * c) - (a2 * c) * c)));
}

// A half vector with density GTR1's D(h) cos(theta_h), with log2_a2 =
// log2(a^2) (Closure::clearcoat_log2_a2).
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> gtr1_sample(D d, V ux, V uy, V a, V log2_a2) {
  const V zero = Zero(d), one = Set(d, 1.0f);
  const V a2 = a * a;
  // cos^2 = (1 - a2^(1-u)) / (1 - a2), in [0, 1]; clamp the rounding
  // (std::clamp's order: below 0, then above 1; a NaN stays).
  // sin^2 = (a2^(1-u) - a2) / (1 - a2), its own quotient rather than
  // 1 - cos^2, which near the peak moves in steps of 6e-8 (6 % of a2 at
  // gloss 1): the half vectors came out on rings.
  const V e = exp2_lanes(d, (one - ux) * log2_a2);
  const V q = (one - e) / (one - a2);
  const V cos2 = IfThenElse(q < zero, zero, IfThenElse(one < q, one, q));
  const V cos_h = Sqrt(cos2);
  const V sin_h = Sqrt(Max((e - a2) / (one - a2), zero));
  V sin_phi, cos_phi;
  sin_cos_turn(d, uy, sin_phi, cos_phi);
  return {sin_h * cos_phi, sin_h * sin_phi, cos_h};
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_BSDF_MICROFACET_INL_H_ toggle
