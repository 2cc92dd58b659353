#include "core/bsdf/fresnel.h"

#include "core/bsdf/dielectric-inl.h"
#include "core/simd/width1.h"

namespace pathlab::fresnel {

float dielectric(float cos_i, float eta) {
  using namespace width1;
  return generic::fresnel_dielectric(kScalar, F{cos_i}, F{eta}).raw;
}

}  // namespace pathlab::fresnel
