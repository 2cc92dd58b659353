// Materials as the scene describes them: a small tagged record per material,
// resolved by name when the scene is loaded. The lobes a material is made of
// are listed in `Lobe`; a compiled scene records which lobes any of its
// materials use (its LobeMask) so that shading can skip what a scene does not
// need. The Disney model will add its lobes here without changing the
// Surfel interface.
//
// Scene-file parameters (object "materials": { "<name>": {...} }):
//
//   type "diffuse"   Lambertian reflector
//     albedo        [r,g,b] in [0,1]   reflectance                 default [0.5,0.5,0.5]
//     emission      [r,g,b] >= 0       emitted radiance            default [0,0,0]
//     two_sided     bool               emit from both sides        default false
//     light         bool               register the emission as a  default true
//                                      light for light sampling; false leaves it to rays that hit it
//
//   type "mirror"    perfect specular reflector (an impulse)
//     reflectance   [r,g,b] in [0,1]                                default [1,1,1]
//     emission, two_sided, light        as for "diffuse"
//
//   type "emissive"  emits, reflects nothing (a black body that glows)
//     radiance      [r,g,b] >= 0       emitted radiance            required
//     two_sided, light                  as for "diffuse"
//
// Emission leaves the front side of a surface: the side its geometric normal
// points to (see each shape's "flip_normals"), or both sides if two_sided.
#pragma once

#include "core/math.h"

#include <cstdint>
#include <string>

namespace pathlab {

enum class MaterialType : std::uint8_t { Diffuse, Mirror, Emissive };

// The lobes materials are built from. A path event names the lobe that
// scattered it; a LobeMask has bit (1 << lobe) set for each lobe in use.
enum class Lobe : std::uint8_t {
  Lambert,       // cos/pi diffuse
  MirrorImpulse, // perfect specular reflection (a Dirac delta)
  Count
};
using LobeMask = std::uint32_t;
inline constexpr LobeMask lobe_bit(Lobe l) { return LobeMask{1} << static_cast<unsigned>(l); }
const char* lobe_name(Lobe lobe);

struct Material {
  std::string name;
  MaterialType type = MaterialType::Diffuse;
  Spectrum albedo{0.5f};       // diffuse albedo, or mirror reflectance
  Spectrum emission{0.0f};     // emitted radiance
  bool two_sided_emission = false;
  bool sampled_as_light = true;  // false: only rays that hit it find its emission

  bool emits() const { return !is_black(emission); }
  // True if the material scatters light at all (an "emissive" does not).
  bool scatters() const { return type != MaterialType::Emissive && !is_black(albedo); }
  // True if every way this material scatters is an impulse: next-event
  // estimation can never connect through it.
  bool is_pure_impulse() const { return type == MaterialType::Mirror; }
  LobeMask lobes() const;
};

const char* material_type_name(MaterialType type);

}  // namespace pathlab
