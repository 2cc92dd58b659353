// The buffer views of pathlab-debug as 8-bit RGBA for a texture. A view is
// any layer of the render or of an image file (layers.h) drawn with one of
// the mappings below, or the NaN/Inf map. No window needed.
#pragma once

#include "debugtools/gui/layers.h"
#include "debugtools/gui/session.h"

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace pathlab::debug {

// How a layer's values become colours:
//   tone    radiance: scaled by 2^exposure, clamped, sRGB-encoded (beauty, albedo, L0..Ln)
//   normal  0.5 + 0.5 v per channel (unit vectors)
//   id      a distinct colour per integer value (material ids; negative: black)
//   linear  the mean of the layer's channels mapped from its range [lo, hi]
//           onto the colour ramp (ramp_colour), lo -> dark blue, hi -> yellow
//   log     as linear, of log10 of the mean over [log10 lo, log10 hi] (values <= 0: black)
enum class Mapping : std::uint8_t { Tone, Normal, Id, Linear, Log };
inline constexpr Mapping kAllMappings[] = {Mapping::Tone, Mapping::Normal, Mapping::Id, Mapping::Linear, Mapping::Log};
const char* mapping_name(Mapping m);  // "tone", "normal", "id", "linear", "log"
std::optional<Mapping> parse_mapping(std::string_view name);

// The mapping a layer is shown with until the user picks another: tone for
// RGB(A) layers (beauty, albedo, per-bounce radiance) except those named like
// a statistic (variance, error, ...), normal for "normal", id for
// "material", linear (auto-ranged) for everything else: variance, depth,
// path length, sample counts, any stage buffer.
Mapping default_mapping(const Layer& layer);

// The value a linear / log view maps: the mean of the first min(count, 3) channels.
float layer_scalar(const Layer& layer, std::size_t pixel);

// The range a linear or log view maps onto the ramp: the smallest and largest
// finite value (log: positive value) of layer_scalar. lo == hi when the
// layer is constant (then everything is drawn at the ramp's middle);
// `valid` is false when there is no finite (positive) value at all.
struct Range {
  float lo = 0.0f, hi = 1.0f;
  bool valid = false;
};
Range auto_range(const Layer& layer, Mapping mapping);

// The colour ramp of linear and log views at t in [0, 1] (viridis-like:
// dark blue, teal, green, yellow), as display (sRGB) values in [0, 1].
vec3 ramp_colour(float t);

// RGBA bytes of `layer`, row-major, top row first. Non-finite values are
// magenta in every mapping.
std::vector<std::uint8_t> layer_rgba(const Layer& layer, Mapping mapping, float exposure, const Range& range);

// The NaN/Inf map: pixels with a non-finite sample (`nonfinite` > 0) in red
// over the dimmed beauty image.
std::vector<std::uint8_t> nonfinite_rgba(const Layer& beauty, const Layer& nonfinite, float exposure);

}  // namespace pathlab::debug
