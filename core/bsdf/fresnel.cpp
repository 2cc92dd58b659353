#include "core/bsdf/fresnel.h"

#include "core/bsdf/dielectric-inl.h"
#include "core/bsdf/disney-inl.h"
#include "core/simd/width1.h"

namespace pathlab::fresnel {

float schlick_weight(float c) {
  using namespace width1;
  return generic::schlick_weight(kScalar, F{c}).raw;
}

float dielectric(float cos_i, float eta) {
  using namespace width1;
  return generic::fresnel_dielectric(kScalar, F{cos_i}, F{eta}).raw;
}

}  // namespace pathlab::fresnel
