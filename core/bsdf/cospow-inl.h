// The cosine-power lobe of core/bsdf/cospow.h written once over Highway's
// vectors: core/bsdf/disney.cpp calls it at width 1 (core/simd/width1.h) for
// both tracers' scalar code under `bsdf_sampling: cospow`, the wavefront's
// vectorised stages at their SIMD width (disney-inl.h's CospowLobes). Float
// throughout, with pathlab's own logarithm and exponentials
// (core/simd/sampling-inl.h), so that every target and width rounds alike.
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_BSDF_COSPOW_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_BSDF_COSPOW_INL_H_
#undef PATHLAB_CORE_BSDF_COSPOW_INL_H_
#else
#define PATHLAB_CORE_BSDF_COSPOW_INL_H_
#endif

#include <hwy/highway.h>

#include "core/bsdf/cospow.h"
#include "core/math.h"
#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"
#include "core/simd/sampling-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// The exponent n = 2 / alpha^2 - 2 (Walter et al.'s Beckmann-Phong
// correspondence), clamped to [0, cospow::kMaxExponent] in std::clamp's
// order (alpha = 0 gives the cap).
template <class D, class V = VecOf<D>>
HWY_INLINE V cospow_exponent(D d, V alpha) {
  const V n = Set(d, 2.0f) / (alpha * alpha) - Set(d, 2.0f);
  const V cap = Set(d, cospow::kMaxExponent);
  return IfThenElse(n < Zero(d), Zero(d), IfThenElse(cap < n, cap, n));
}

// A direction about the unit axis r with density (n + 1) / (2 pi) cos^n:
// cos = ux^(1/(n+1)), taken as 1 - cos = -expm1(ln(ux) / (n + 1)) (at
// n = 1e6 cos itself is within 1e-6 of 1, where floats are 6e-8 apart, so
// the angles would come out quantised, and exactly 0 for most ux); ux = 0
// gives the rim (cos = 0). The azimuth is 2 pi uy. Normalised.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> cospow_sample(D d, const Vec3<V>& r, V n, V ux, V uy) {
  const V zero = Zero(d), one = Set(d, 1.0f);
  const auto rim = Not(ux > zero);
  const V log_u = log_lanes(d, IfThenElse(rim, one, ux));  // ux >= 2^-24 elsewhere: a normal float
  const V one_minus_c = IfThenElse(rim, one, Neg(expm1_lanes(d, log_u / (n + one))));
  const V c = one - one_minus_c;
  const V s = Sqrt(Max(one_minus_c * (Set(d, 2.0f) - one_minus_c), zero));
  V sin_phi, cos_phi;
  sin_cos_turn(d, uy, sin_phi, cos_phi);
  Vec3<V> fs, ft;
  frame(d, r, fs, ft);
  return normalize(d, to_world(fs, ft, r, s * cos_phi, s * sin_phi, c));
}

// The density of cospow_sample's direction wi (unit) about r: (n + 1) /
// (2 pi) cos^n on the half of the sphere around r, 0 beyond. 1 - cos comes
// from the chord, |wi - r|^2 / 2 (a dot product near 1 loses the digits
// that cos^1e6 depends on), and cos^n = e^(n ln(1 - (1 - cos))) by
// log1p_lanes and exp_lanes: relative error about 2.4e-7 |n ln cos|, below
// 3e-6 wherever the density is above 1e-5 of its peak.
template <class D, class V = VecOf<D>>
HWY_INLINE V cospow_pdf(D d, const Vec3<V>& r, V n, const Vec3<V>& wi) {
  const Vec3<V> chord = wi - r;
  const V one_minus_c = Set(d, 0.5f) * dot(chord, chord);
  const auto inside = one_minus_c < Set(d, 1.0f);
  const V log_c = log1p_lanes(d, Neg(IfThenElseZero(inside, one_minus_c)));
  const V density = ((n + Set(d, 1.0f)) * Set(d, static_cast<float>(0.5 / 3.14159265358979323846))) *
                    exp_lanes(d, n * log_c);
  return IfThenElseZero(inside, density);
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_BSDF_COSPOW_INL_H_ toggle
