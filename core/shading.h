// How a compiled scene shades: the per-scene choices that reach every
// Surfel call without changing how the tracers call it (each Material of a
// CompiledScene carries a copy, set by configure_shading()).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace pathlab {

// How glossy lobes are sampled (RenderSettings::bsdf_sampling).
enum class BsdfSampling : std::uint8_t {
  Vndf,    // exact GGX visible-normal sampling (Heitz 2018); the default
  Cospow,  // cosine-power lobes about the mirror direction (course notes)
};
const char* bsdf_sampling_name(BsdfSampling s);
std::optional<BsdfSampling> parse_bsdf_sampling(std::string_view name);

// The shading code a scene runs, from the lobes its materials use.
enum class ShadingPath : std::uint8_t {
  LambertOnly,      // no Disney material: Lambert, mirror, dielectric code only
  Disney,           // Disney lobes compiled in, GTR1 compiled out
  DisneyClearcoat,  // Disney lobes and GTR1
  General,          // every material through the full Disney-capable closure
                    // (a Lambert material as a Lambert-weighted closure)
};
const char* shading_path_name(ShadingPath p);

struct ShadingConfig {
  ShadingPath path = ShadingPath::General;  // safe for any material
  BsdfSampling sampling = BsdfSampling::Vndf;
  // BSDF samples with a smaller density are discarded (a firefly control
  // that trades bias for variance; 0 = off).
  float min_pdf = 0.0f;
};

}  // namespace pathlab
