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

float Ggx::g(const vec3& w) const {
  using namespace width1;
  return generic::ggx_g(kScalar, F{ax}, F{ay}, lanes(w)).raw;
}

vec3 Ggx::sample_visible(const vec3& wo, vec2 u) const {
  using namespace width1;
  return scalars(generic::ggx_sample_visible(kScalar, F{ax}, F{ay}, lanes(wo), F{u.x}, F{u.y}));
}

vec3 reflect(const vec3& wo, const vec3& h) {
  using namespace width1;
  return scalars(generic::reflect(lanes(wo), lanes(h)));
}

vec3 half_vector(const vec3& wo, const vec3& wi) {
  using namespace width1;
  return scalars(generic::half_vector(kScalar, lanes(wo), lanes(wi)));
}

}  // namespace microfacet

namespace gtr1 {

float D(float cos_h, float a) {
  using namespace width1;
  return generic::gtr1_D(kScalar, F{cos_h}, F{a}, F{log_alpha2(a)}).raw;
}

float g(float c, float a) {
  using namespace width1;
  return generic::gtr1_g(kScalar, F{c}, F{a}).raw;
}

vec3 sample(vec2 u, float a) {
  using namespace width1;
  return scalars(generic::gtr1_sample(kScalar, F{u.x}, F{u.y}, F{a}, F{log2_alpha2(a)}));
}

}  // namespace gtr1

}  // namespace pathlab
