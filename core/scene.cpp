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

namespace {

// Whether each shape is in the image: a group's shapes are only if an
// instance places the group.
std::vector<bool> placed_shapes(const Scene& scene) {
  std::vector<bool> placed(scene.shapes.size(), true);
  for (const ShapeGroup& g : scene.groups)
    for (const std::uint32_t i : g.shapes) placed[i] = false;
  for (const Instance& inst : scene.instances)
    for (const std::uint32_t i : scene.groups[inst.group].shapes) placed[i] = true;
  return placed;
}

}  // namespace

std::optional<EmitterPeak> brightest_constant_emitter(const Scene& scene) {
  std::optional<EmitterPeak> peak;
  const auto take = [&](const Spectrum& L, const auto& source) {
    const float radiance = max_component(glm::abs(L));
    if (std::isnan(radiance)) return;  // a scene built in code (the loaders refuse NaN)
    if (!peak || radiance > peak->radiance) peak = EmitterPeak{radiance, source()};
  };
  if (scene.environment && !is_black(*scene.environment))
    take(*scene.environment, [] { return std::string("the environment"); });
  bool other_lights = scene.environment_map || !scene.delta_lights.empty();
  const std::vector<bool> placed = placed_shapes(scene);
  for (std::size_t i = 0; i < scene.shapes.size(); ++i) {
    const Material& m = scene.materials[scene.shapes[i].material];
    if (!placed[i] || !m.emits()) continue;
    if (m.emission_textured)
      other_lights = true;
    else
      take(m.emission, [&] { return "material '" + m.name + "'"; });
  }
  if (peak) peak->bounds_every_light = !other_lights;
  return peak;
}

std::optional<float> constant_emitters_peak(const Scene& scene) {
  const std::optional<EmitterPeak> peak = brightest_constant_emitter(scene);
  if (!peak || !peak->bounds_every_light) return std::nullopt;
  return peak->radiance;
}

}  // namespace pathlab
