#include "debugtools/material_override.h"

namespace pathlab {

const char* material_override_name(MaterialOverride o) {
  switch (o) {
    case MaterialOverride::Authored: return "authored";
    case MaterialOverride::WhiteLambert: return "white";
    case MaterialOverride::Mirror: return "mirror";
  }
  return "?";
}

std::optional<MaterialOverride> parse_material_override(std::string_view name) {
  for (MaterialOverride o : {MaterialOverride::Authored, MaterialOverride::WhiteLambert, MaterialOverride::Mirror})
    if (name == material_override_name(o)) return o;
  return std::nullopt;
}

Scene override_materials(Scene scene, MaterialOverride o) {
  if (o == MaterialOverride::Authored) return scene;
  for (Material& m : scene.materials) {
    if (m.type == MaterialType::Emissive) continue;
    Material replaced;  // defaults for everything the override does not set
    replaced.name = m.name;
    replaced.type = o == MaterialOverride::Mirror ? MaterialType::Mirror : MaterialType::Diffuse;
    replaced.albedo = Spectrum(1.0f);
    replaced.emission = m.emission;
    replaced.two_sided_emission = m.two_sided_emission;
    replaced.sampled_as_light = m.sampled_as_light;
    m = replaced;
  }
  return scene;
}

}  // namespace pathlab
