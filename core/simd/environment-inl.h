// The lat-long conventions written once over Highway's vectors: an
// environment image's (core/environment_map.h: a direction in the map's
// frame to its (u, v) and back, and (u, v) to its texel) and a textured
// sphere's texture coordinates (core/texture.h). core/environment_map.cpp,
// core/texture.cpp and core/compiled_scene.cpp call them at width 1
// (core/simd/width1.h) for both tracers' scalar code, the wavefront's
// vectorised stages at their SIMD width (an escaped ray's sky, the map's
// light samples, and hits on textured spheres).
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_SIMD_ENVIRONMENT_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_SIMD_ENVIRONMENT_INL_H_
#undef PATHLAB_CORE_SIMD_ENVIRONMENT_INL_H_
#else
#define PATHLAB_CORE_SIMD_ENVIRONMENT_INL_H_
#endif

#include <hwy/highway.h>

#include "core/math.h"
#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"
#include "core/simd/lights-inl.h"
#include "core/simd/sampling-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// EnvironmentMap::direction_to_uv: u by the azimuth atan2(x, -z) (the half
// turn below 0 is the map's second half; u = 1 - tiny rounding up to 1 is
// the left edge of column 0 again), v by theta = atan2(sin theta, y): acos(y)
// loses all precision near the poles, where y rounds to 1 long before x and
// z do.
template <class D, class V = VecOf<D>>
HWY_INLINE void env_direction_to_uv(D d, const Vec3<V>& local, V& u, V& v) {
  V a = atan2_lanes(d, local.x, Neg(local.z)) * Set(d, kInv2Pi);
  a = IfThenElse(a < Zero(d), a + Set(d, 1.0f), a);
  u = IfThenElseZero(a < Set(d, 1.0f), a);
  v = atan2_lanes(d, Sqrt(local.x * local.x + local.z * local.z), local.y) * Set(d, kInvPi);
}

// EnvironmentMap::uv_to_direction, with sin theta: theta = pi v, phi = 2 pi u,
// d = (sin theta sin phi, cos theta, -sin theta cos phi).
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> env_uv_to_direction(D d, V u, V v, V& sin_theta) {
  V cos_theta, sin_phi, cos_phi;
  sin_cos_turn(d, Set(d, 0.5f) * v, sin_theta, cos_theta);
  sin_cos_turn(d, u, sin_phi, cos_phi);
  return {sin_theta * sin_phi, cos_theta, Neg(sin_theta) * cos_phi};
}

// EnvironmentMap::texel_of along one axis: the cell of uv in [0, 1] among
// `size` (whole float), clamped to [0, size - 1] (NaN to 0: x86's max
// returns its second operand, lane1's too).
template <class D, class V = VecOf<D>>
HWY_INLINE V env_texel(D d, V uv, V size) {
  return Min(Max(Floor(uv * size), Zero(d)), size - Set(d, 1.0f));
}

// The density in solid angle of a direction whose lat-long cell has density
// `uv_pdf` in (u, v) (Distribution2D::pdf), at sin theta: uv_pdf / (2 pi^2
// sin theta), 0 at a pole.
template <class D, class V = VecOf<D>>
HWY_INLINE V env_solid_angle_pdf(D d, V uv_pdf, V sin_theta) {
  return IfThenElseZero(sin_theta > Zero(d), uv_pdf / (Set(d, 2.0f * kPi * kPi) * sin_theta));
}

// EnvironmentMap::lookup: the texel (x, y) of a direction in the map's
// frame among width x height (whole floats), and the density in solid
// angle with which the map samples it: Distribution2D::pdf of that cell
// (its cdfs read as distribution2d_sample reads them) at sin theta from the
// direction itself, not the texel.
template <class D, class M, class Cdfs, class V = VecOf<D>>
HWY_INLINE V env_lookup(D d, M m, const Vec3<V>& local, std::size_t width, std::size_t height, const Cdfs& cdfs, V& x,
                        V& y) {
  V u, v;
  env_direction_to_uv(d, local, u, v);
  x = env_texel(d, u, Set(d, static_cast<float>(width)));
  y = env_texel(d, v, Set(d, static_cast<float>(height)));
  const V uv_pdf = cdf_density(d, m, height, [&](M valid, V i) { return cdfs.row(valid, i); }, y) *
                   cdf_density(d, m, width, [&](M valid, V i) { return cdfs.column(valid, y, i); }, x);
  // From x and z, not 1 - y^2, which is 0 within 3e-4 rad of a pole in float.
  return env_solid_angle_pdf(d, uv_pdf, Sqrt(local.x * local.x + local.z * local.z));
}

// EnvironmentMap::sample's direction (turned into the world by the columns
// c0, c1, c2) for the point (px, py) that distribution2d_sample drew with
// density uv_pdf, and its density in solid angle (the texel drawn's, as
// pbrt-v4's ImageInfiniteLight: a point within rounding of a texel's edge
// can map back into its neighbour). Lanes where either density is 0 or
// infinite, or the point is a pole, leave ok.
template <class D, class M, class V = VecOf<D>>
HWY_INLINE Vec3<V> env_sample_direction(D d, M& ok, V px, V py, V uv_pdf, const Vec3<V>& c0, const Vec3<V>& c1,
                                        const Vec3<V>& c2, V& pdf) {
  V sin_theta;
  const Vec3<V> local = env_uv_to_direction(d, px, py, sin_theta);
  ok = And(ok, And(uv_pdf > Zero(d), sin_theta > Zero(d)));
  const Vec3<V> wi = normalize(d, to_world(c0, c1, c2, local.x, local.y, local.z));
  pdf = env_solid_angle_pdf(d, uv_pdf, sin_theta);
  ok = And(ok, Not(IsInf(pdf)));
  return wi;
}

// A sphere's texture coordinates at the direction `dir` from its centre (in
// its own space, about unit length): pbrt's (phi, theta) about the z axis,
// u = phi / 2 pi in [0, 1) (a half turn below 0 is the second half; u = 1 -
// tiny rounding up to 1 is 0 again, as the environment's), v = 1 - theta / pi
// (1 at +z). theta = atan2(sin theta, z) with sin theta = sqrt(x^2 + y^2),
// which the footprint reads too: acos(z) loses all precision near the
// poles, where z rounds to 1 long before x and y do.
template <class D, class V = VecOf<D>>
HWY_INLINE void sphere_uv(D d, const Vec3<V>& dir, V& u, V& v, V& sin_theta) {
  V a = atan2_lanes(d, dir.y, dir.x) * Set(d, kInv2Pi);
  a = IfThenElse(a < Zero(d), a + Set(d, 1.0f), a);
  u = IfThenElseZero(a < Set(d, 1.0f), a);
  sin_theta = Sqrt(dir.x * dir.x + dir.y * dir.y);
  v = Set(d, 1.0f) - atan2_lanes(d, sin_theta, dir.z) * Set(d, kInvPi);
}

// The uv area per world area of a sphere of `radius` at sin theta (its
// sphere_uv): dA = r^2 sin theta dtheta dphi = 2 pi^2 r^2 sin theta du dv,
// sin theta at least 1e-4 (the poles, where a texel shrinks to a point).
template <class D, class V = VecOf<D>>
HWY_INLINE V sphere_uv_per_area(D d, V radius, V sin_theta) {
  return Set(d, 1.0f) / (Set(d, 2.0f * kPi * kPi) * radius * radius * Max(sin_theta, Set(d, 1e-4f)));
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_ENVIRONMENT_INL_H_ toggle
