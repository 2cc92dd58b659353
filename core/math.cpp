#include "core/math.h"

#include "core/simd/width1.h"

namespace pathlab {

// The generic frame() (core/simd/lanes-inl.h) at width 1: the very code the
// wavefront's lanes run.
Frame::Frame(const vec3& normal) : n(normal) {
  using namespace width1;
  F3 ls, lt;
  generic::frame(kScalar, lanes(normal), ls, lt);
  s = scalars(ls);
  t = scalars(lt);
}

}  // namespace pathlab
