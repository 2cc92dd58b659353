// The buffer views of pathlab-debug as 8-bit RGBA for a texture: beauty,
// albedo, shading normal, depth, material id, variance, path length and the
// NaN/Inf map. No window needed.
#pragma once

#include "debugtools/gui/session.h"

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace pathlab::debug {

enum class View : std::uint8_t { Beauty, Albedo, Normal, Depth, Material, Variance, PathLength, NonFinite };
inline constexpr View kAllViews[] = {View::Beauty,   View::Albedo,   View::Normal,     View::Depth,
                                     View::Material, View::Variance, View::PathLength, View::NonFinite};
const char* view_name(View v);  // "beauty", "albedo", "normal", "depth", "material", "variance", "pathlength", "nan"
std::optional<View> parse_view(std::string_view name);

// RGBA bytes, row-major, top row first. `exposure` (stops) scales beauty and
// variance; depth, variance and path length are shown relative to their
// largest value; normals as 0.5 + 0.5 n; material ids as distinct colours;
// the NaN/Inf map marks pixels with a non-finite sample in red over a dimmed
// beauty image.
std::vector<std::uint8_t> view_rgba(const Snapshot& snap, View view, float exposure);

}  // namespace pathlab::debug
