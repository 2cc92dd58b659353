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

vec3 Frame::to_local(const vec3& v) const {
  using namespace width1;
  return scalars(generic::to_local(lanes(s), lanes(t), lanes(n), lanes(v)));
}

vec3 Frame::to_world(const vec3& v) const {
  using namespace width1;
  return scalars(generic::to_world(lanes(s), lanes(t), lanes(n), F{v.x}, F{v.y}, F{v.z}));
}

}  // namespace pathlab
