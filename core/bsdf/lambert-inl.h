// The Lambertian lobe written once over Highway's vectors: core/bsdf/
// lambert.h calls it at width 1 (core/simd/width1.h), for both tracers'
// scalar code, and the wavefront's vectorised stages at their SIMD width.
// In the local shading frame, z the normal on the side of the outgoing
// direction; reflection only: directions at or below the horizon get
// nothing.
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_BSDF_LAMBERT_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_BSDF_LAMBERT_INL_H_
#undef PATHLAB_CORE_BSDF_LAMBERT_INL_H_
#else
#define PATHLAB_CORE_BSDF_LAMBERT_INL_H_
#endif

#include <hwy/highway.h>

#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"
#include "core/simd/sampling-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// lambert::eval and lambert::pdf: f cos = albedo cos_i / pi and the cosine
// density, both 0 unless cos_i (wi's local z) > 0.
template <class D, class V = VecOf<D>>
HWY_INLINE void lambert_eval(D d, const Vec3<V>& albedo, V cos_i, Vec3<V>& f, V& pdf) {
  pdf = cosine_hemisphere_pdf(d, cos_i);
  f = zero_unless(cos_i > Zero(d), (cos_i * Set(d, kInvPi)) * albedo);
}

// lambert::sample: a cosine-weighted local direction wi and its density,
// where the density is usable: not on the disk's rim (pdf 0: grazing, no
// energy) and not below min_pdf (a NaN passes, as a comparison's false
// does in the scalar code). Its weight f cos / pdf is the albedo exactly.
template <class D, class V = VecOf<D>>
HWY_INLINE auto lambert_sample(D d, V ux, V uy, V min_pdf, Vec3<V>& wi, V& pdf) {
  cosine_hemisphere(d, ux, uy, wi.x, wi.y, wi.z);
  pdf = cosine_hemisphere_pdf(d, wi.z);
  return And(Not(pdf <= Zero(d)), Not(pdf < min_pdf));
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_BSDF_LAMBERT_INL_H_ toggle
