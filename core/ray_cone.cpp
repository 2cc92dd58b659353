#include "core/ray_cone.h"

#include "core/simd/width1.h"

namespace pathlab {

RayCone scattered_cone(const RayCone& in, float t, bool impulse, float pdf, TextureFilter filter) {
  if (filter == TextureFilter::Point) return {};
  using namespace width1;
  F width, spread;
  generic::scattered_cone(kScalar, F{in.width}, F{in.spread}, F{t}, lane1::M{impulse}, F{pdf}, width, spread);
  return {width.raw, spread.raw};
}

}  // namespace pathlab
