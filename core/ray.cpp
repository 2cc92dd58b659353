#include "core/ray.h"

#include "core/simd/lanes-inl.h"

#include <hwy/highway.h>

namespace pathlab {

// Written once for every SIMD width (core/simd/lanes-inl.h): the
// wavefront's vectorised stages run the same source.
vec3 offset_ray_origin(const vec3& p, const vec3& error, const vec3& n) {
  namespace hn = hwy::HWY_NAMESPACE;
  constexpr hn::CappedTag<float, 1> d;
  using V3 = HWY_NAMESPACE::Vec3<hn::Vec<decltype(d)>>;
  auto lanes = [d](const vec3& v) { return V3{hn::Set(d, v.x), hn::Set(d, v.y), hn::Set(d, v.z)}; };
  // A point with no rounding error across its surface (every vertex on a
  // coordinate plane through the origin: a PLY or glTF ground at y = 0)
  // gets no offset from its bound, and Embree reports hits at t = tnear = 0,
  // so its rays would find the surface again: the generic code moves it by
  // one float of its largest coordinate (2^-100 at the origin, far above
  // the denormals); p + offset is itself rounded: one more float away.
  const V3 o = HWY_NAMESPACE::offset_ray_origin(d, lanes(p), lanes(error), lanes(n));
  return vec3(hn::GetLane(o.x), hn::GetLane(o.y), hn::GetLane(o.z));
}

}  // namespace pathlab
