// The perfect mirror written once over Highway's vectors: core/bsdf/mirror.h
// calls it at width 1 (core/simd/width1.h), the wavefront's vectorised
// stages at their SIMD width. A Dirac delta in the reflected direction: no
// density a light sample could hit (eval and pdf are 0 everywhere), so only
// its sampling is here.
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_BSDF_MIRROR_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_BSDF_MIRROR_INL_H_
#undef PATHLAB_CORE_BSDF_MIRROR_INL_H_
#else
#define PATHLAB_CORE_BSDF_MIRROR_INL_H_
#endif

#include <hwy/highway.h>

#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// The mirror's impulse for wo_local (the local frame flipped so that wo is
// on +z): the reflection about +z, chosen with probability equal to the
// mean reflectance (std::min(1, average(albedo)); absorbed otherwise, so the
// weight albedo / prob stays near 1 and paths end in proportion to the
// energy they would lose). False where u_lobe falls in the absorbed part.
template <class D, class V = VecOf<D>>
HWY_INLINE auto mirror_sample(D d, const Vec3<V>& albedo, V u_lobe, const Vec3<V>& wo_local, Vec3<V>& wi_local,
                              Vec3<V>& weight, V& pdf) {
  pdf = Min(average(d, albedo), Set(d, 1.0f));
  wi_local = {Neg(wo_local.x), Neg(wo_local.y), wo_local.z};
  weight = albedo / pdf;
  return u_lobe < pdf;
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_BSDF_MIRROR_INL_H_ toggle
