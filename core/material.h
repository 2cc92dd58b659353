// Materials as the scene describes them: a small tagged record per material,
// resolved by name when the scene is loaded. The lobes a material is made of
// are listed in `Lobe`; a compiled scene records which lobes any of its
// materials use (its LobeMask) so that shading can skip what a scene does not
// need (core/shading.h). The lobes themselves live one per file in
// core/bsdf/.
//
// Scene-file parameters (object "materials": { "<name>": {...} }):
//
//   type "diffuse"   Lambertian reflector
//     albedo        [r,g,b] in [0,1]   reflectance                 default [0.5,0.5,0.5]
//     emission      [r,g,b] >= 0       emitted radiance            default [0,0,0]
//     two_sided     bool               emit from both sides        default false
//     light         bool               register the emission as a  default true
//                                      light for light sampling; false leaves it to rays that hit it
//     one_sided     bool               reflect on the front side   default false
//                                      only; the back is black (Mitsuba 3's diffuse without
//                                      "twosided", glTF's doubleSided false)
//
//   type "mirror"    perfect specular reflector (an impulse)
//     reflectance   [r,g,b] in [0,1]                                default [1,1,1]
//     emission, two_sided, light, one_sided  as for "diffuse"
//
//   type "disney"    Burley's principled BRDF (core/bsdf/disney.h); every
//                    parameter but base_color is a number in [0, 1]
//     base_color      [r,g,b] in [0,1]  diffuse colour / metal F0       default [0.8,0.8,0.8]
//     metallic        0 dielectric .. 1 metal                           default 0
//     subsurface      0 Disney diffuse .. 1 subsurface approximation    default 0
//     specular        dielectric F0 = 0.08 specular (0.5 = ior 1.5)     default 0.5
//     specular_tint   tints the dielectric F0 towards base_color        default 0
//     roughness       GGX alpha = roughness^2 (floored at 1e-3)         default 0.5
//     anisotropic     aspect sqrt(1 - 0.9 anisotropic), along tangent x default 0
//     sheen           grazing cloth sheen                               default 0
//     sheen_tint      tints the sheen towards base_color                default 0.5
//     clearcoat       strength of the GTR1 clear coat (weight 0.25 x)   default 0
//     clearcoat_gloss GTR1 alpha = mix(0.1, 0.001, clearcoat_gloss)     default 1
//     energy_compensation  bool: couple the lobes as layers so that the   default false
//                     directional albedo never exceeds 1 (core/bsdf/energy.h);
//                     false is Burley's published model, which reflects up
//                     to 1.65x the incident light at grazing views
//     emission, two_sided, light, one_sided  as for "diffuse"
//
//   type "dielectric" smooth glass: Fresnel reflection + Snell refraction
//                    (two impulses, chosen by probability). The geometric
//                    normal's side is the outside ("flip_normals" swaps it).
//     ior             index of refraction inside / outside, in [1, 10]  default 1.5
//     reflectance     [r,g,b] in [0,1]  tint of the reflected part      default [1,1,1]
//     transmittance   [r,g,b] in [0,1]  tint of the refracted part      default [1,1,1]
//     Radiance is not rescaled by eta^2 across the interface: the factors
//     cancel on every path that enters and leaves, which is every path when
//     camera and lights are outside; this keeps the weight of white glass at
//     exactly 1 so Russian roulette never ends its paths early.
//
//   type "emissive"  emits, reflects nothing (a black body that glows)
//     radiance      [r,g,b] >= 0       emitted radiance            required
//     two_sided, light                  as for "diffuse"
//
// Every type:
//     alpha         number in [0, 1]   coverage: a ray meets the   default 1
//                   or texture         surface with this probability and passes through it
//                                      otherwise (core/alpha.h); an error on a light and on a sphere;
//                                      a texture is read at its nearest texel, one channel, linear
//
// Emission leaves the front side of a surface: the side its geometric normal
// points to (see each shape's "flip_normals"), or both sides if two_sided.
// Reflection happens on both sides unless one_sided: then a path that meets
// the back (wo on the back of the geometric surface) ends there, and light
// arriving from behind is not reflected (Surfel::eval and scatter).
#pragma once

#include "core/bsdf/closure.h"
#include "core/math.h"
#include "core/shading.h"
#include "core/texture.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pathlab {

enum class MaterialType : std::uint8_t { Diffuse, Mirror, Emissive, Disney, Dielectric };

// The lobes materials are built from. A path event names the lobe that
// scattered it; a LobeMask has bit (1 << lobe) set for each lobe in use.
enum class Lobe : std::uint8_t {
  Lambert,       // cos/pi diffuse
  MirrorImpulse, // perfect specular reflection (a Dirac delta)
  DisneyDiffuse, // Burley diffuse with retro-reflection and subsurface approximation
  Sheen,         // Burley sheen
  Specular,      // anisotropic GGX (GTR2) with Smith masking, Schlick Fresnel
  Clearcoat,     // GTR1 clear coat
  DielectricReflection,    // smooth dielectric, Fresnel-reflected impulse
  DielectricTransmission,  // smooth dielectric, refracted impulse
  Count
};
using LobeMask = std::uint32_t;
inline constexpr LobeMask lobe_bit(Lobe l) { return LobeMask{1} << static_cast<unsigned>(l); }
inline constexpr LobeMask kDisneyLobeMask =
    lobe_bit(Lobe::DisneyDiffuse) | lobe_bit(Lobe::Sheen) | lobe_bit(Lobe::Specular) | lobe_bit(Lobe::Clearcoat);
const char* lobe_name(Lobe lobe);

// Parameters of type "dielectric".
struct DielectricParams {
  float ior = 1.5f;
  Spectrum reflectance{1.0f};
  Spectrum transmittance{1.0f};
};

// The parameters a scene may texture (docs/scene-format.md, "Textures").
enum class MaterialParam : std::uint8_t {
  Albedo,              // diffuse albedo, mirror reflectance
  Emission,            // emission ("radiance" of an emissive)
  GlassReflectance,
  GlassTransmittance,
  BaseColor,           // the Disney parameters from here on
  Metallic,
  Subsurface,
  Specular,
  SpecularTint,
  Roughness,
  Anisotropic,
  Sheen,
  SheenTint,
  Clearcoat,
  ClearcoatGloss,
};
struct TexturedParam {
  MaterialParam param;
  TextureRef texture;
};
// A tangent-space normal map (glTF's convention: +y up, n = 2 c - 1 with
// x and y times `scale`). The loaders keep |scale| <= kMaxNormalMapScale: the
// tilted normal's squared length (x s)^2 + (y s)^2 + z^2 must be a float.
inline constexpr float kMaxNormalMapScale = 1e6f;
struct NormalMap {
  TextureRef texture;
  float scale = 1.0f;
};

// A material's parameters at one point of its surface: what a textured
// material evaluates per hit (CompiledScene::resolve) and Surfel reads
// instead of the Material's own.
struct SurfaceParams {
  Spectrum albedo{0.0f};    // Material::albedo
  Spectrum emission{0.0f};  // Material::emission
  DielectricParams glass{};
  disney::Closure closure{};
};

struct Material {
  std::string name;
  MaterialType type = MaterialType::Diffuse;
  Spectrum albedo{0.5f};       // diffuse albedo, or mirror reflectance
  Spectrum emission{0.0f};     // emitted radiance
  bool two_sided_emission = false;
  bool sampled_as_light = true;  // false: only rays that hit it find its emission
  bool one_sided = false;      // reflects on its front side only; the back is black
  // Coverage in [0, 1]: a ray meets the surface with this probability and
  // passes through it otherwise (core/alpha.h). 1: opaque. A texture, when
  // there is one, replaces the number: its nearest texel at the hit's
  // texture coordinates, clamped to [0, 1] (Textures::nearest_number).
  float alpha = 1.0f;
  std::optional<TextureRef> alpha_texture{};
  // >= 0: the coverage is a mask, 1 where it is at least this and 0 below
  // (glTF's alphaMode MASK and alphaCutoff); < 0: stochastic coverage.
  float alpha_cutoff = -1.0f;
  DisneyParams disney{};       // type Disney
  DielectricParams glass{};    // type Dielectric
  // Derived from `disney` (or, for the general path, from `albedo`) by the
  // factories below and configure_shading().
  disney::Closure closure{};

  bool emits() const { return !is_black(emission) || emission_textured; }
  // True if rays may pass through the surface (EmbreeAccel then registers
  // its alpha filter on the material's shapes, and only then).
  bool has_alpha() const { return alpha < 1.0f || alpha_texture.has_value(); }
  // True if the material scatters light at all (an "emissive" does not).
  bool scatters() const;
  // True if every way this material scatters is an impulse: next-event
  // estimation can never connect through it.
  bool is_pure_impulse() const { return type == MaterialType::Mirror || type == MaterialType::Dielectric; }
  LobeMask lobes() const;

  // Set by configure_shading() when a scene is compiled; the default suits
  // a material used on its own (tests).
  ShadingConfig shading{};

  // Parameters read from textures (each overrides the constant above), and
  // the normal map; both empty for an untextured material, whose hits read
  // the constants and pay nothing for textures.
  std::vector<TexturedParam> textured{};
  std::optional<NormalMap> normal_map{};
  bool emission_textured = false;  // `textured` holds Emission (kept by set_texture)
  bool is_textured() const { return !textured.empty(); }
  // Whether resolving a hit on it reads textures: a textured parameter or a
  // normal map (CompiledScene::resolve; alpha is Embree's filter's).
  bool reads_textures_at_hits() const { return is_textured() || normal_map.has_value(); }
  const TexturedParam* texture_of(MaterialParam p) const;
  // Reads parameter `p` from `texture` from now on.
  void set_texture(MaterialParam p, const TextureRef& texture);
};

// The parameters of `m` at a point: reflection's filtered over `at`'s
// footprint, emission's read at `at.uv` without filtering (emission_at; see
// docs/scene-format.md). Disney parameters are clamped to their ranges,
// colours to >= 0 and reflectances to <= 1.
void evaluate_textured(const Material& m, const Textures& textures, const TextureFootprint& at, SurfaceParams* out);
// The emission of `m` at a point (its constant, or its texture read without
// filtering): what a hit and a light sample there both see.
Spectrum emission_at(const Material& m, const Textures* textures, vec2 uv);

// Materials of each type with the given parameters (and no emission).
Material diffuse_material(const Spectrum& albedo);
Material disney_material(const DisneyParams& params);
Material dielectric_material(const DielectricParams& params);

struct Scene;
// The shading path a scene with these lobes runs; `force_general` routes
// every material through the full Disney-capable closure.
ShadingPath shading_path_for(LobeMask lobes, bool force_general);
// Stamps every material of `scene` with the scene's ShadingConfig (from its
// render settings and the lobes its shapes' materials use).
void configure_shading(Scene& scene);

const char* material_type_name(MaterialType type);

}  // namespace pathlab
