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

}  // namespace pathlab
