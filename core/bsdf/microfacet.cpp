#include "core/bsdf/microfacet.h"

#include "core/bsdf/gtr1.h"
#include "core/bsdf/microfacet-inl.h"
#include "core/simd/width1.h"

namespace pathlab {

namespace microfacet {

float Ggx::D(const vec3& h) const {
  using namespace width1;
  return generic::ggx_D(kScalar, F{ax}, F{ay}, lanes(h)).raw;
}

vec3 reflect(const vec3& wo, const vec3& h) {
  using namespace width1;
  return scalars(generic::reflect(lanes(wo), lanes(h)));
}

}  // namespace microfacet

namespace gtr1 {

float D(const vec3& h, float a) {
  using namespace width1;
  return generic::gtr1_D(kScalar, lanes(h), F{a}, F{log_alpha2(a)}).raw;
}

}  // namespace gtr1

}  // namespace pathlab
