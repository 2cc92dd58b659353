#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "tests/simd_kernels.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h

#include <hwy/highway.h>

#include "core/bsdf/disney-inl.h"
#include "core/simd/lanes-inl.h"
#include "core/simd/sampling-inl.h"
#include "core/simd/spherical-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pathlab::test::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
namespace warps = pathlab::HWY_NAMESPACE;

template <class D>
void warp_lanes(D d, const float* ux, const float* uy, float* x, float* y, float* z, float* s, float* c) {
  using V = hn::Vec<D>;
  V vx, vy, vz, vs, vc;
  const V a = hn::LoadU(d, ux), b = hn::LoadU(d, uy);
  warps::cosine_hemisphere(d, a, b, vx, vy, vz);
  warps::sin_cos_quarter(d, a * hn::Set(d, 3.14159265358979323846f / 4.0f), vs, vc);
  hn::StoreU(vx, d, x), hn::StoreU(vy, d, y), hn::StoreU(vz, d, z), hn::StoreU(vs, d, s), hn::StoreU(vc, d, c);
}

void simd_warps(const float* ux, const float* uy, float* x, float* y, float* z, float* s, float* c, std::size_t n) {
  const hn::ScalableTag<float> d;
  const std::size_t lanes = hn::Lanes(d);
  std::size_t i = 0;
  for (; i + lanes <= n; i += lanes) warp_lanes(d, ux + i, uy + i, x + i, y + i, z + i, s + i, c + i);
  const hn::CappedTag<float, 1> one;
  for (; i < n; ++i) warp_lanes(one, ux + i, uy + i, x + i, y + i, z + i, s + i, c + i);
}

template <class D>
void offset_lanes(D d, const float* p, const float* e, const float* n, float* out) {
  using V = hn::Vec<D>;
  constexpr std::size_t kMax = hn::MaxLanes(D());
  const std::size_t lanes = hn::Lanes(d);
  // Interleaved xyz to one array per coordinate, and back.
  float in[9][kMax];
  for (std::size_t i = 0; i < lanes; ++i)
    for (int k = 0; k < 3; ++k) in[k][i] = p[3 * i + k], in[3 + k][i] = e[3 * i + k], in[6 + k][i] = n[3 * i + k];
  const auto load = [&](int k) {
    return warps::Vec3<V>{hn::LoadU(d, in[k]), hn::LoadU(d, in[k + 1]), hn::LoadU(d, in[k + 2])};
  };
  const warps::Vec3<V> r = warps::offset_ray_origin(d, load(0), load(3), load(6));
  float o[3][kMax];
  hn::StoreU(r.x, d, o[0]), hn::StoreU(r.y, d, o[1]), hn::StoreU(r.z, d, o[2]);
  for (std::size_t i = 0; i < lanes; ++i)
    for (int k = 0; k < 3; ++k) out[3 * i + k] = o[k][i];
}

void simd_offset_ray_origin(const float* p, const float* error, const float* normal, float* out, std::size_t n) {
  const hn::ScalableTag<float> d;
  const std::size_t lanes = hn::Lanes(d);
  std::size_t i = 0;
  for (; i + lanes <= n; i += lanes) offset_lanes(d, p + 3 * i, error + 3 * i, normal + 3 * i, out + 3 * i);
  const hn::CappedTag<float, 1> one;
  for (; i < n; ++i) offset_lanes(one, p + 3 * i, error + 3 * i, normal + 3 * i, out + 3 * i);
}

template <unsigned F, class Lobes>
void disney_lanes(const float* in, float* out, std::size_t n) {
  using D = hn::ScalableTag<float>;
  using V = hn::Vec<D>;
  const D d;
  const std::size_t lanes = hn::Lanes(d);
  for (std::size_t i = 0; i < n; i += lanes) {
    const auto at = [&](int k) { return hn::LoadU(d, in + k * n + i); };
    const auto at3 = [&](int k) { return warps::Vec3<V>{at(k), at(k + 1), at(k + 2)}; };
    const V zero = hn::Zero(d);
    const warps::ClosureLanes<V> c{{zero, zero, zero}, at3(0), at(3), at(4), at3(5), at(8), at3(9), at(12), at(13),
                                   at(14), at(15), at(16), at(17)};
    const warps::Vec3<V> wo = at3(18), wi = at3(21);
    const warps::NoEnergy energy;
    const Lobes lobes;
    const auto put = [&](int k, V v) { hn::StoreU(v, d, out + k * n + i); };
    const warps::Vec3<V> f = warps::disney_eval<F>(d, c, wo, wi, energy, {});
    put(0, f.x), put(1, f.y), put(2, f.z);
    put(3, warps::disney_pdf<F>(d, c, wo, wi, lobes, energy, {}));
    V p[3];
    warps::disney_lobe_probabilities<F>(d, c, wo.z, Lobes::kKeepsCosine, energy, p);
    put(4, p[0]), put(5, p[1]), put(6, p[2]);
    warps::Vec3<V> s;
    V family;
    const auto drawn = warps::disney_sample<F>(d, c, wo, at(24), at(25), at(26), lobes, energy, s, family);
    put(7, s.x), put(8, s.y), put(9, s.z);
    put(10, hn::IfThenElseZero(drawn, hn::Set(d, 1.0f)));
    put(11, family);
  }
}

void simd_disney(bool clearcoat, bool cospow, const float* in, float* out, std::size_t n) {
  if (cospow) {
    if (clearcoat) disney_lanes<3u, warps::CospowLobes>(in, out, n);
    else disney_lanes<1u, warps::CospowLobes>(in, out, n);
  } else {
    if (clearcoat) disney_lanes<3u, warps::VndfLobes>(in, out, n);
    else disney_lanes<1u, warps::VndfLobes>(in, out, n);
  }
}

void simd_log_exp(const float* in, float* out, std::size_t n) {
  const hn::ScalableTag<float> d;
  for (std::size_t i = 0; i < n; i += hn::Lanes(d)) {
    hn::StoreU(warps::log_lanes(d, hn::LoadU(d, in + i)), d, out + i);
    hn::StoreU(warps::log1p_lanes(d, hn::LoadU(d, in + n + i)), d, out + n + i);
    hn::StoreU(warps::exp_lanes(d, hn::LoadU(d, in + 2 * n + i)), d, out + 2 * n + i);
    hn::StoreU(warps::expm1_lanes(d, hn::LoadU(d, in + 3 * n + i)), d, out + 3 * n + i);
  }
}

void simd_transcendentals(const float* u, const float* y, float* sin, float* cos, float* exp2, std::size_t n) {
  const hn::ScalableTag<float> d;
  for (std::size_t i = 0; i < n; i += hn::Lanes(d)) {
    hn::Vec<decltype(d)> s, c;
    warps::sin_cos_turn(d, hn::LoadU(d, u + i), s, c);
    hn::StoreU(s, d, sin + i), hn::StoreU(c, d, cos + i);
    hn::StoreU(warps::exp2_lanes(d, hn::LoadU(d, y + i)), d, exp2 + i);
  }
}

void simd_atan2(const float* y, const float* x, float* out, std::size_t n) {
  const hn::ScalableTag<float> d;
  for (std::size_t i = 0; i < n; i += hn::Lanes(d))
    hn::StoreU(warps::atan2_lanes(d, hn::LoadU(d, y + i), hn::LoadU(d, x + i)), d, out + i);
}

void simd_trig_d(const double* x, const double* y, double* sin, double* cos, double* atan2, std::size_t n) {
  const hn::ScalableTag<double> d;
  for (std::size_t i = 0; i < n; i += hn::Lanes(d)) {
    hn::Vec<decltype(d)> s, c;
    warps::sin_cos_d(d, hn::LoadU(d, x + i), s, c);
    hn::StoreU(s, d, sin + i), hn::StoreU(c, d, cos + i);
    hn::StoreU(warps::atan2_d(d, hn::LoadU(d, y + i), hn::LoadU(d, x + i)), d, atan2 + i);
  }
}

}  // namespace pathlab::test::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "tests/simd_kernels.h"

namespace pathlab::test {
HWY_EXPORT(simd_warps);
void simd_warps(const float* ux, const float* uy, float* x, float* y, float* z, float* s, float* c, std::size_t n) {
  HWY_DYNAMIC_DISPATCH(simd_warps)(ux, uy, x, y, z, s, c, n);
}
HWY_EXPORT(simd_disney);
void simd_disney(bool clearcoat, bool cospow, const float* in, float* out, std::size_t n) {
  HWY_DYNAMIC_DISPATCH(simd_disney)(clearcoat, cospow, in, out, n);
}
HWY_EXPORT(simd_log_exp);
void simd_log_exp(const float* in, float* out, std::size_t n) { HWY_DYNAMIC_DISPATCH(simd_log_exp)(in, out, n); }
HWY_EXPORT(simd_transcendentals);
void simd_transcendentals(const float* u, const float* y, float* sin, float* cos, float* exp2, std::size_t n) {
  HWY_DYNAMIC_DISPATCH(simd_transcendentals)(u, y, sin, cos, exp2, n);
}
HWY_EXPORT(simd_atan2);
void simd_atan2(const float* y, const float* x, float* out, std::size_t n) {
  HWY_DYNAMIC_DISPATCH(simd_atan2)(y, x, out, n);
}
HWY_EXPORT(simd_trig_d);
void simd_trig_d(const double* x, const double* y, double* sin, double* cos, double* atan2, std::size_t n) {
  HWY_DYNAMIC_DISPATCH(simd_trig_d)(x, y, sin, cos, atan2, n);
}
HWY_EXPORT(simd_offset_ray_origin);
void simd_offset_ray_origin(const float* p, const float* error, const float* normal, float* out, std::size_t n) {
  HWY_DYNAMIC_DISPATCH(simd_offset_ray_origin)(p, error, normal, out, n);
}
}  // namespace pathlab::test
#endif
