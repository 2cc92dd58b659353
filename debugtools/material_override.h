// Debug views of a scene's materials: every scattering material made white
// Lambert, or a perfect mirror, before the scene is compiled. Emission (and
// how it is sampled) is kept, so lights stay lights.
#pragma once

#include "core/scene.h"

#include <optional>
#include <string_view>

namespace pathlab {

enum class MaterialOverride : std::uint8_t { Authored, WhiteLambert, Mirror };

const char* material_override_name(MaterialOverride o);  // "authored", "white", "mirror"
std::optional<MaterialOverride> parse_material_override(std::string_view name);

// `scene` with every material that scatters replaced as `o` says. Materials
// that only emit (type "emissive") are left as they are.
Scene override_materials(Scene scene, MaterialOverride o);

}  // namespace pathlab
