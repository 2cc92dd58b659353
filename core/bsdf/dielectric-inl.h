// The smooth dielectric interface written once over Highway's vectors:
// core/bsdf/dielectric.h and fresnel.cpp call it at width 1
// (core/simd/width1.h), the wavefront's vectorised stages at their SIMD
// width. Fresnel reflection and Snell refraction, both impulses. Local
// frame with z = the geometric normal of the front (outside) side: a
// direction with z > 0 is outside; ior = the inside's index relative to the
// outside's.
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_BSDF_DIELECTRIC_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_BSDF_DIELECTRIC_INL_H_
#undef PATHLAB_CORE_BSDF_DIELECTRIC_INL_H_
#else
#define PATHLAB_CORE_BSDF_DIELECTRIC_INL_H_
#endif

#include <hwy/highway.h>

#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// fresnel::dielectric (core/bsdf/fresnel.h): the unpolarised reflectance of
// a smooth interface, eta = n_transmitted / n_incident, cos_i clamped to
// [0, 1] (std::clamp's selects); 1 under total internal reflection. At
// cos_i = 0 both ratios are -1 exactly (their denominators are > 0 there).
template <class D, class V = VecOf<D>>
HWY_INLINE V fresnel_dielectric(D d, V cos_i, V eta) {
  const V zero = Zero(d), one = Set(d, 1.0f);
  cos_i = IfThenElse(cos_i < zero, zero, IfThenElse(one < cos_i, one, cos_i));
  const V sin2_t = (one - cos_i * cos_i) / (eta * eta);
  const V cos_t = Sqrt(one - sin2_t);  // NaN under total internal reflection, selected away
  const V r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const V r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return IfThenElse(sin2_t >= one, one, Set(d, 0.5f) * (r_par * r_par + r_perp * r_perp));
}

// The interface's impulses for wo_local: reflection or refraction with
// probability proportional to the energy each carries (F times the mean
// reflectance tint, (1 - F) times the mean transmittance tint; absorbed
// otherwise, so for white tints the weight is 1). False where u_lobe falls
// in the absorbed part or wo grazes exactly (no projected area: nothing
// scatters); `transmitted` says which impulse. `fresnel_ignored` plants the
// test-only fault DielectricFresnelIgnored (core/faults.h), which only
// core's fault build passes (a parameter, so that this template is the same
// in every translation unit).
template <class D, class M, class V = VecOf<D>>
HWY_INLINE auto dielectric_sample(D d, V ior, const Vec3<V>& reflectance, const Vec3<V>& transmittance, V u_lobe,
                                  const Vec3<V>& wo_local, Vec3<V>& wi_local, Vec3<V>& weight, V& pdf, M& transmitted,
                                  bool fresnel_ignored = false) {
  const V zero = Zero(d), one = Set(d, 1.0f);
  // Entering (wo outside) or leaving decides the relative index.
  const auto entering = wo_local.z > zero;
  const V eta = IfThenElse(entering, ior, one / ior);
  const V cos_o = Abs(wo_local.z);
  V F = fresnel_dielectric(d, cos_o, eta);
  if (fresnel_ignored) F = IfThenElseZero(F >= one, one);  // Fresnel reflection dropped, total internal reflection kept
  const V p_r = F * average(d, reflectance);
  const V p_t = (one - F) * average(d, transmittance);
  const auto reflected = u_lobe < p_r;
  transmitted = And(Not(reflected), u_lobe < p_r + p_t);
  // Snell's law (chosen only where F < 1: sin2_t < 1; the max clamps rounding).
  const V sin2_t = (one - cos_o * cos_o) / (eta * eta);
  const V cos_t = Sqrt(Max(one - sin2_t, zero));
  const V side = IfThenElse(entering, one, Set(d, -1.0f));
  // -wo / eta + (0, 0, side (cos_o / eta - cos_t)), the zeros added as the scalar vec3 sum adds them (-0 + 0 = +0).
  const Vec3<V> refracted = normalize(d, Vec3<V>{Neg(wo_local.x) / eta + zero, Neg(wo_local.y) / eta + zero,
                                                 Neg(wo_local.z) / eta + side * (cos_o / eta - cos_t)});
  const Vec3<V> mirrored{Neg(wo_local.x), Neg(wo_local.y), wo_local.z};
  wi_local = select(reflected, mirrored, refracted);
  weight = select(reflected, (F / p_r) * reflectance, ((one - F) / p_t) * transmittance);
  pdf = IfThenElse(reflected, p_r, p_t);
  return And(Not(wo_local.z == zero), Or(reflected, transmitted));
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_BSDF_DIELECTRIC_INL_H_ toggle
