#include "core/strategy_weights.h"

#include "core/faults.h"
#include "core/simd/width1.h"

namespace pathlab {

float emission_weight(Strategy strategy, const PreviousVertex& prev, float light_pdf) {
  if (PATHLAB_FAULT(EmissionAfterNee)) return 1.0f;
  using namespace width1;
  return generic::emission_weight(kScalar, strategy, lane1::M{prev.impulse}, lane1::M{prev.bsdf_technique},
                                  F{prev.pdf}, F{light_pdf})
      .raw;
}

float light_sample_weight(Strategy strategy, float light_pdf, float bsdf_pdf) {
  using namespace width1;
  return generic::light_sample_weight(kScalar, strategy, F{light_pdf}, F{bsdf_pdf}).raw;
}

Spectrum delta_light_contribution(const Spectrum& f, const Spectrum& Le, float pdf) {
  using namespace width1;
  return scalars(generic::delta_light_contribution(lanes(f), lanes(Le), F{pdf}));
}

Spectrum light_contribution(const Spectrum& f, const Spectrum& Le, float weight, float pdf) {
  using namespace width1;
  return scalars(generic::light_contribution(lanes(f), lanes(Le), F{weight}, F{pdf}));
}

bool survives_roulette(const Spectrum& beta, float u, Spectrum* weight, float* survival) {
  using namespace width1;
  F3 w = lanes(*weight);
  F s;
  const bool survives = generic::roulette(kScalar, lane1::M{true}, lanes(beta), F{u}, w, s).raw;
  *weight = scalars(w);
  *survival = s.raw;
  return survives;
}

bool samples_area_lights(Strategy strategy, LazyDraw u_technique) {
  using namespace width1;
  return generic::samples_area_lights(kScalar, strategy, lane1::M{true}, [&] { return F{u_technique()}; }).raw;
}

PreviousVertex previous_vertex(Strategy strategy, const Surfel& s, const vec3& wo, const BsdfSample& bs,
                               LazyDraw u_technique) {
  using namespace width1;
  const auto v = generic::previous_vertex(kScalar, strategy, lane1::M{true}, lanes(s.p), lanes(s.n), lanes(wo),
                                          F{bs.pdf}, lane1::M{bs.impulse}, [&] { return F{u_technique()}; });
  return {{scalars(v.p), scalars(v.n)}, v.pdf.raw, v.impulse.raw, v.bsdf_technique.raw};
}

}  // namespace pathlab
