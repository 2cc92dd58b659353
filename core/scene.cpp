#include "core/scene.h"

#include "core/math.h"

#include <algorithm>

namespace pathlab {

const char* strategy_name(Strategy s) {
  switch (s) {
    case Strategy::Cosine: return "cosine";
    case Strategy::Bsdf: return "bsdf";
    case Strategy::Light: return "light";
    case Strategy::LightBsdf: return "light+bsdf";
    case Strategy::Mis: return "mis";
  }
  return "?";
}

std::optional<Strategy> parse_strategy(std::string_view name) {
  for (Strategy s : kAllStrategies)
    if (name == strategy_name(s)) return s;
  return std::nullopt;
}

std::vector<std::string_view> strategy_names() {
  std::vector<std::string_view> names;
  for (Strategy s : kAllStrategies) names.push_back(strategy_name(s));
  return names;
}

const char* light_sampling_name(LightSampling s) { return s == LightSampling::SolidAngle ? "solid_angle" : "area"; }

std::optional<LightSampling> parse_light_sampling(std::string_view name) {
  for (LightSampling s : {LightSampling::Area, LightSampling::SolidAngle})
    if (name == light_sampling_name(s)) return s;
  return std::nullopt;
}

const char* light_sampler_name(LightSamplerKind k) { return k == LightSamplerKind::Bvh ? "bvh" : "power"; }

std::optional<LightSamplerKind> parse_light_sampler(std::string_view name) {
  for (LightSamplerKind k : {LightSamplerKind::Power, LightSamplerKind::Bvh})
    if (name == light_sampler_name(k)) return k;
  return std::nullopt;
}

const char* intersection_name(Intersection i) { return i == Intersection::Fast ? "fast" : "robust"; }

std::optional<Intersection> parse_intersection(std::string_view name) {
  for (Intersection i : {Intersection::Robust, Intersection::Fast})
    if (name == intersection_name(i)) return i;
  return std::nullopt;
}

std::optional<float> constant_emitters_peak(const Scene& scene) {
  if (scene.environment_map || !scene.delta_lights.empty()) return std::nullopt;
  std::optional<float> peak;
  const auto take = [&](const Spectrum& L) { peak = std::max(peak.value_or(0.0f), max_component(glm::abs(L))); };
  if (scene.environment && !is_black(*scene.environment)) take(*scene.environment);
  // A group's shapes are in the image only if an instance places the group.
  std::vector<bool> placed(scene.shapes.size(), true);
  for (const ShapeGroup& g : scene.groups)
    for (const std::uint32_t i : g.shapes) placed[i] = false;
  for (const Instance& inst : scene.instances)
    for (const std::uint32_t i : scene.groups[inst.group].shapes) placed[i] = true;
  for (std::size_t i = 0; i < scene.shapes.size(); ++i) {
    if (!placed[i]) continue;
    const Shape& shape = scene.shapes[i];
    const Material& m = scene.materials[shape.material];
    if (m.emission_textured) return std::nullopt;
    if (m.emits()) take(m.emission);
  }
  return peak;
}

}  // namespace pathlab
