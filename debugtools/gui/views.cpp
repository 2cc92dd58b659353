#include "debugtools/gui/views.h"

#include <algorithm>
#include <cmath>

namespace pathlab::debug {

const char* mapping_name(Mapping m) {
  switch (m) {
    case Mapping::Tone: return "tone";
    case Mapping::Normal: return "normal";
    case Mapping::Id: return "id";
    case Mapping::Linear: return "linear";
    case Mapping::Log: return "log";
  }
  return "?";
}

std::optional<Mapping> parse_mapping(std::string_view name) {
  for (Mapping m : kAllMappings)
    if (name == mapping_name(m)) return m;
  return std::nullopt;
}

Mapping default_mapping(const Layer& layer) {
  const std::string& n = layer.name;
  if (n == "normal") return Mapping::Normal;
  if (n == "material") return Mapping::Id;
  for (const char* statistic : {"variance", "error", "stddev", "sigma", "count"})
    if (n.find(statistic) != std::string::npos) return Mapping::Linear;
  if (layer.channels.rfind("R,G,B", 0) == 0) return Mapping::Tone;
  return Mapping::Linear;
}

float layer_scalar(const Layer& layer, std::size_t pixel) {
  const vec3& v = layer.image.pixels[pixel];
  const int k = std::clamp(layer.count, 1, 3);
  float sum = 0.0f;
  for (int c = 0; c < k; ++c) sum += v[c];
  return sum / static_cast<float>(k);
}

Range auto_range(const Layer& layer, Mapping mapping) {
  Range r;
  r.lo = INFINITY;
  r.hi = -INFINITY;
  for (std::size_t i = 0; i < layer.image.pixels.size(); ++i) {
    const float v = layer_scalar(layer, i);
    if (!std::isfinite(v) || (mapping == Mapping::Log && v <= 0.0f)) continue;
    r.lo = std::min(r.lo, v);
    r.hi = std::max(r.hi, v);
  }
  r.valid = r.lo <= r.hi;
  if (!r.valid) r.lo = 0.0f, r.hi = 1.0f;
  return r;
}

vec3 ramp_colour(float t) {
  // Viridis at five stops, linearly interpolated.
  static const vec3 stops[] = {{0.267f, 0.005f, 0.329f}, {0.230f, 0.322f, 0.546f}, {0.128f, 0.567f, 0.551f},
                               {0.369f, 0.789f, 0.383f}, {0.993f, 0.906f, 0.144f}};
  const float x = std::clamp(std::isfinite(t) ? t : 0.0f, 0.0f, 1.0f) * 4.0f;
  const int i = std::min(static_cast<int>(x), 3);
  return glm::mix(stops[i], stops[i + 1], x - static_cast<float>(i));
}

namespace {

std::uint8_t byte(float v) { return static_cast<std::uint8_t>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); }

// A distinct, stable colour per material id (golden-ratio hue steps).
vec3 id_colour(float id) {
  if (id < 0.0f) return vec3(0.0f);
  const float h = std::fmod(id * 0.618034f, 1.0f) * 6.0f;
  const float f = h - std::floor(h);
  const vec3 rgb[] = {{1, f, 0}, {1 - f, 1, 0}, {0, 1, f}, {0, 1 - f, 1}, {f, 0, 1}, {1, 0, 1 - f}};
  return 0.25f + 0.7f * rgb[static_cast<int>(h) % 6];
}

void put(std::uint8_t* o, const vec3& display) {
  for (int k = 0; k < 3; ++k) o[k] = byte(display[k]);
  o[3] = 255;
}

const vec3 kMagenta(1.0f, 0.0f, 1.0f);

}  // namespace

std::vector<std::uint8_t> layer_rgba(const Layer& layer, Mapping mapping, float exposure, const Range& range) {
  const std::size_t n = layer.image.pixels.size();
  std::vector<std::uint8_t> out(n * 4, 255);
  const float scale = std::exp2(exposure);
  const bool log = mapping == Mapping::Log;
  const float lo = log ? std::log10(std::max(range.lo, 1e-38f)) : range.lo;
  const float hi = log ? std::log10(std::max(range.hi, 1e-38f)) : range.hi;
  for (std::size_t i = 0; i < n; ++i) {
    const vec3& v = layer.image.pixels[i];
    std::uint8_t* o = &out[4 * i];
    if (!is_finite(v)) {
      put(o, kMagenta);
      continue;
    }
    switch (mapping) {
      case Mapping::Tone: {
        const vec3 c = v * scale;
        put(o, vec3(linear_to_srgb(c.x), linear_to_srgb(c.y), linear_to_srgb(c.z)));
        break;
      }
      case Mapping::Normal: put(o, 0.5f + 0.5f * v); break;
      case Mapping::Id: put(o, id_colour(v.x)); break;
      case Mapping::Linear:
      case Mapping::Log: {
        const float s = layer_scalar(layer, i);
        if (log && s <= 0.0f) {
          put(o, vec3(0.0f));
          break;
        }
        const float x = log ? std::log10(s) : s;
        put(o, ramp_colour(hi > lo ? (x - lo) / (hi - lo) : 0.5f));
        break;
      }
    }
  }
  return out;
}

std::vector<std::uint8_t> nonfinite_rgba(const Layer& beauty, const Layer& nonfinite, float exposure) {
  const std::size_t n = beauty.image.pixels.size();
  std::vector<std::uint8_t> out(n * 4, 255);
  const float scale = 0.25f * std::exp2(exposure);
  for (std::size_t i = 0; i < n; ++i) {
    const vec3 c = beauty.image.pixels[i] * scale;
    if (i < nonfinite.image.pixels.size() && nonfinite.image.pixels[i].x > 0.0f) put(&out[4 * i], vec3(1, 0, 0));
    else if (!is_finite(c)) put(&out[4 * i], kMagenta);
    else put(&out[4 * i], vec3(linear_to_srgb(c.x), linear_to_srgb(c.y), linear_to_srgb(c.z)));
  }
  return out;
}

}  // namespace pathlab::debug
