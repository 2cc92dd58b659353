#include "core/scene.h"

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

}  // namespace pathlab
