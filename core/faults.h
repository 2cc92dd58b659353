// Test-only fault switches: the classic path-tracing mistakes, planted on
// demand so that tests can prove the checker catches each one (a checker
// that passes a planted bug is broken).
//
// They exist only in builds compiled with PATHLAB_FAULT_INJECTION, which
// only tests/ does (pathlab_core_faults, pathlab_reference_faults,
// pathlab_wavefront_faults). In every
// other build PATHLAB_FAULT(name) is the constant false and the faulty
// branches vanish.
#pragma once

namespace pathlab {

enum class Fault {
  None,
  BsdfPdfOff5Percent,     // surfel.cpp: the Lambert lobe reports pdf * 1.05 (and weights by it)
  CosineDropped,          // surfel.cpp: the Lambert lobe's f |cos| loses its cosine
  EmissionAfterNee,       // reference: emission counted in full after next-event estimation
  LightPdfWithoutArea,    // light_sampler.cpp: area density 1 instead of 1 / area
  LightPdfWithoutDistance,// light_sampler.cpp: no distance^2 in the area -> solid-angle conversion
  RouletteNotReweighted,  // reference: a roulette survivor is not divided by its probability
  SpecularPdfOff5Percent, // bsdf/disney.cpp: the GGX lobe reports pdf * 1.05
  VndfPdfWithoutJacobian, // bsdf/disney.cpp: the VNDF pdf lacks the reflection Jacobian 1 / (4 wo.h)
  SmithG1Dropped,         // bsdf/disney.cpp: the specular f loses the masking G1(wi) of the light direction
  SpecularNoDenominator,  // bsdf/disney.cpp: the specular f = D F G without its 1 / (4 cos_i cos_o)
  HorizonUnclamped,       // bsdf/disney.cpp: eval and pdf no longer return 0 for wi below the surface
  CoatNotCoupled,         // bsdf/disney.cpp: energy compensation forgets to dim what lies under the clearcoat
  DiffuseNotCoupled,      // bsdf/disney.cpp: energy compensation forgets to dim the diffuse under the specular layer
  DielectricFresnelIgnored,// surfel.cpp: glass always refracts (Fresnel reflection dropped, TIR kept)
  AlphaKeysNotSet,        // reference: every ray keeps alpha key 0, so each triangle decides once for all rays
  WavefrontMisWeightLostAtDepth2,  // wavefront (scalar stages): emission a continuation ray finds after two
                                   // bounces (vertex 3) is counted with weight 1, its MIS weight lost
};

#ifdef PATHLAB_FAULT_INJECTION
// The fault in force for the whole process (tests set it, single-threaded,
// before rendering).
inline Fault g_fault = Fault::None;
#define PATHLAB_FAULT(name) (::pathlab::g_fault == ::pathlab::Fault::name)
#else
#define PATHLAB_FAULT(name) false
#endif

}  // namespace pathlab
