#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "tests/simd_kernels.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h

#include <hwy/highway.h>

#include "core/simd/sampling-inl.h"

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

}  // namespace pathlab::test::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "tests/simd_kernels.h"

namespace pathlab::test {
HWY_EXPORT(simd_warps);
void simd_warps(const float* ux, const float* uy, float* x, float* y, float* z, float* s, float* c, std::size_t n) {
  HWY_DYNAMIC_DISPATCH(simd_warps)(ux, uy, x, y, z, s, c, n);
}
}  // namespace pathlab::test
#endif
