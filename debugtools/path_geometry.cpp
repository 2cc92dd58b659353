#include "debugtools/path_geometry.h"

#include <type_traits>

namespace pathlab {

std::vector<PathLine> path_lines(const PathRecorder& path, std::uint32_t sample, float escape_length) {
  PathLine line{PathLine::Kind::Path, sample, {}};
  std::vector<PathLine> shadows;
  vec3 last_p(0.0f), last_dir(0.0f);  // where the current ray starts and goes
  Spectrum beta(1.0f);                // throughput after the last scatter
  const auto current = [&]() -> PathPoint& { return line.points.back(); };

  for (const PathEvent& event : path.events()) {
    std::visit(
        [&](const auto& e) {
          using E = std::decay_t<decltype(e)>;
          if constexpr (std::is_same_v<E, CameraEvent>) {
            line.points.push_back({e.origin, 0, Spectrum(1.0f), Spectrum(0.0f), 0.0f, -1, kPointCamera});
            last_p = e.origin;
            last_dir = e.dir;
          } else if constexpr (std::is_same_v<E, HitEvent>) {
            line.points.push_back({e.p, e.vertex, e.throughput, e.added, 0.0f, -1, 0});
            last_p = e.p;
          } else if constexpr (std::is_same_v<E, EscapeEvent>) {
            line.points.push_back(
                {last_p + last_dir * escape_length, e.vertex, beta, e.added, 0.0f, -1, kPointEscape});
          } else if constexpr (std::is_same_v<E, LightEvent>) {
            if (e.rejected != LightRejection::None) return;  // no shadow ray was traced
            if (!line.points.empty()) {
              current().added += e.added;
              if (e.visible) current().flags |= kPointNeeVisible;
            }
            const std::uint32_t visible = e.visible ? kPointNeeVisible : 0u;
            const vec3 end = e.infinite ? last_p + e.wi * escape_length : e.point;
            const Spectrum throughput = line.points.empty() ? Spectrum(1.0f) : current().throughput;
            PathLine shadow{PathLine::Kind::Shadow, sample, {}};
            shadow.points.push_back({last_p, e.vertex, throughput, e.added, e.pdf, -1, visible});
            shadow.points.push_back({end, e.vertex, throughput, Spectrum(0.0f), e.pdf, -1, visible | kPointLight});
            shadows.push_back(std::move(shadow));
          } else if constexpr (std::is_same_v<E, ScatterEvent>) {
            if (!line.points.empty()) {
              current().pdf = e.pdf;
              current().lobe = static_cast<int>(e.lobe);
              if (e.impulse) current().flags |= kPointImpulse;
            }
            beta = e.throughput;
            last_dir = e.wi;
          } else if constexpr (std::is_same_v<E, EndEvent>) {
            if (e.reason == PathEnd::Roulette && !line.points.empty()) current().flags |= kPointRoulette;
          }
        },
        event);
  }
  std::vector<PathLine> lines;
  lines.reserve(1 + shadows.size());
  lines.push_back(std::move(line));
  for (PathLine& s : shadows) lines.push_back(std::move(s));
  return lines;
}

}  // namespace pathlab
