#include "debugtools/gui/views.h"

#include <algorithm>
#include <cmath>

namespace pathlab::debug {

const char* view_name(View v) {
  switch (v) {
    case View::Beauty: return "beauty";
    case View::Albedo: return "albedo";
    case View::Normal: return "normal";
    case View::Depth: return "depth";
    case View::Material: return "material";
    case View::Variance: return "variance";
    case View::PathLength: return "pathlength";
    case View::NonFinite: return "nan";
  }
  return "?";
}

std::optional<View> parse_view(std::string_view name) {
  for (View v : kAllViews)
    if (name == view_name(v)) return v;
  return std::nullopt;
}

namespace {

std::uint8_t byte(float v) { return static_cast<std::uint8_t>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); }
std::uint8_t srgb_byte(float v) { return byte(linear_to_srgb(v)); }

float largest(const Image& img) {
  float m = 0.0f;
  for (const vec3& p : img.pixels)
    if (std::isfinite(max_component(p))) m = std::max(m, max_component(p));
  return m > 0.0f ? m : 1.0f;
}

// A distinct, stable colour per material id (golden-ratio hue steps).
vec3 id_colour(float id) {
  if (id < 0.0f) return vec3(0.0f);
  const float h = std::fmod(id * 0.618034f, 1.0f) * 6.0f;
  const float f = h - std::floor(h);
  const vec3 rgb[] = {{1, f, 0}, {1 - f, 1, 0}, {0, 1, f}, {0, 1 - f, 1}, {f, 0, 1}, {1, 0, 1 - f}};
  return 0.25f + 0.7f * rgb[static_cast<int>(h) % 6];
}

}  // namespace

std::vector<std::uint8_t> view_rgba(const Snapshot& snap, View view, float exposure) {
  const std::size_t n = static_cast<std::size_t>(snap.width) * snap.height;
  std::vector<std::uint8_t> out(n * 4, 255);
  if (snap.beauty.pixels.size() != n) return out;
  const float scale = std::exp2(exposure);
  const Image* src = &snap.beauty;
  float norm = 1.0f;
  switch (view) {
    case View::Albedo: src = &snap.albedo; break;
    case View::Normal: src = &snap.normal; break;
    case View::Depth: src = &snap.depth, norm = largest(snap.depth); break;
    case View::Material: src = &snap.material; break;
    case View::Variance: src = &snap.variance, norm = largest(snap.variance); break;
    case View::PathLength: src = &snap.path_length, norm = largest(snap.path_length); break;
    case View::Beauty:
    case View::NonFinite: break;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const vec3 v = src->pixels[i];
    std::uint8_t* o = &out[4 * i];
    vec3 c(0.0f);
    bool encoded = false;  // already display values (no sRGB curve)
    switch (view) {
      case View::Beauty: c = v * scale; break;
      case View::Albedo: c = v; break;
      case View::Normal: c = 0.5f + 0.5f * v, encoded = true; break;
      case View::Depth: c = vec3(v.x > 0.0f ? 1.0f - 0.8f * v.x / norm : 0.0f), encoded = true; break;
      case View::Material: c = id_colour(v.x), encoded = true; break;
      case View::Variance: c = vec3((v.x + v.y + v.z) / (3.0f * norm) * scale); break;
      case View::PathLength: c = vec3(v.x / norm), encoded = true; break;
      case View::NonFinite:
        c = snap.nonfinite.pixels[i].x > 0.0f ? vec3(1, 0, 0) : 0.25f * v * scale;
        break;
    }
    if (std::isnan(c.x) || std::isnan(c.y) || std::isnan(c.z)) c = vec3(1, 0, 1), encoded = true;  // magenta
    for (int k = 0; k < 3; ++k) o[k] = encoded ? byte(c[k]) : srgb_byte(c[k]);
  }
  return out;
}

}  // namespace pathlab::debug
