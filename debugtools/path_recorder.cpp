#include "debugtools/path_recorder.h"

#include "core/light_sampler.h"
#include "core/render.h"

#include <cstdio>
#include <sstream>

namespace pathlab {
namespace {

using json = nlohmann::json;

json j3(const vec3& v) { return json::array({v.x, v.y, v.z}); }

std::string fmt3(const vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", static_cast<double>(v.x), static_cast<double>(v.y),
                static_cast<double>(v.z));
  return buf;
}

std::string fmt(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", static_cast<double>(v));
  return buf;
}

const std::string& material_name(const Scene& scene, std::uint32_t m) {
  static const std::string unknown = "?";
  return m < scene.materials.size() ? scene.materials[m].name : unknown;
}

// What a light event sampled: a delta light's own kind ("point", "spot",
// "directional"), "area" or "environment".
const char* light_kind(const Scene& scene, const LightEvent& e) {
  if (!e.delta) return e.infinite ? "environment" : "area";
  const std::vector<const DeltaLight*> lights = sampled_delta_lights(scene);
  if (e.light >= lights.size()) return "point";
  switch (lights[e.light]->kind) {
    case DeltaLight::Kind::Point: return "point";
    case DeltaLight::Kind::Spot: return "spot";
    case DeltaLight::Kind::Directional: return "directional";
  }
  return "point";
}

struct JsonVisitor {
  const Scene& scene;
  json operator()(const CameraEvent& e) const {
    return {{"type", "camera"}, {"film", {e.film.x, e.film.y}}, {"origin", j3(e.origin)}, {"dir", j3(e.dir)}};
  }
  json operator()(const HitEvent& e) const {
    return {{"type", "hit"},          {"vertex", e.vertex},        {"p", j3(e.p)},
            {"n", j3(e.n)},           {"front", e.front},          {"material", material_name(scene, e.material)},
            {"shape", e.shape},       {"prim", e.prim},
            {"instance", e.instance == kNoInstance ? json(nullptr) : json(e.instance)},
            {"emitted", j3(e.emitted)},
            {"emission_weight", e.emission_weight}, {"added", j3(e.added)}, {"throughput", j3(e.throughput)}};
  }
  json operator()(const EscapeEvent& e) const {
    return {{"type", "escape"}, {"vertex", e.vertex}, {"emitted", j3(e.emitted)},
            {"emission_weight", e.emission_weight}, {"added", j3(e.added)}};
  }
  json operator()(const LightEvent& e) const {
    json j = {{"type", "light"}, {"vertex", e.vertex}, {"kind", light_kind(scene, e)},
              {"light", e.light}, {"point", j3(e.point)}, {"wi", j3(e.wi)},
              {"pdf", e.pdf},     {"Le", j3(e.Le)},       {"visible", e.visible},
              {"mis_weight", e.mis_weight}, {"added", j3(e.added)}};
    j["dist"] = std::isinf(e.dist) ? json(nullptr) : json(e.dist);  // null: the environment
    // Why no shadow ray was traced, or null; no_sample: no light was picked.
    j["rejected"] = e.rejected == LightRejection::None ? json(nullptr) : json(light_rejection_name(e.rejected));
    if (e.rejected == LightRejection::NoSample) j["light"] = nullptr;
    return j;
  }
  json operator()(const ScatterEvent& e) const {
    return {{"type", "scatter"}, {"vertex", e.vertex}, {"lobe", e.cosine ? "cosine" : lobe_name(e.lobe)},
            {"impulse", e.impulse}, {"wi", j3(e.wi)}, {"pdf", e.pdf},
            {"weight", j3(e.weight)}, {"survival", e.survival}, {"throughput", j3(e.throughput)}};
  }
  json operator()(const EndEvent& e) const {
    return {{"type", "end"}, {"vertex", e.vertex}, {"reason", path_end_name(e.reason)}};
  }
};

struct TextVisitor {
  const Scene& scene;
  std::ostream& out;
  void operator()(const CameraEvent& e) const {
    out << "camera      film (" << fmt(e.film.x) << ", " << fmt(e.film.y) << ")  origin " << fmt3(e.origin)
        << "  dir " << fmt3(e.dir) << "\n";
  }
  void operator()(const HitEvent& e) const {
    out << "#" << e.vertex << " hit      p " << fmt3(e.p) << "  n " << fmt3(e.n) << (e.front ? "  front" : "  back")
        << "  material '" << material_name(scene, e.material) << "'  shape " << e.shape << " prim " << e.prim;
    if (e.instance != kNoInstance) out << " instance " << e.instance;
    out << "\n";
    if (!is_black(e.emitted))
      out << "   emission  Le " << fmt3(e.emitted) << "  weight " << fmt(e.emission_weight) << "  added "
          << fmt3(e.added) << "\n";
  }
  void operator()(const EscapeEvent& e) const {
    out << "#" << e.vertex << " escape   environment " << fmt3(e.emitted) << "  weight " << fmt(e.emission_weight)
        << "  added " << fmt3(e.added) << "\n";
  }
  void operator()(const LightEvent& e) const {
    if (e.rejected == LightRejection::NoSample) {
      out << "#" << e.vertex << " light    " << (e.delta ? "delta" : "area") << " REJECTED no_sample"
          << "  (the light sampler gave none: zero pdf, back of a one-sided emitter, edge-on or outside a spot cone)\n";
      return;
    }
    if (e.rejected != LightRejection::None) {
      out << "#" << e.vertex << " light    " << light_kind(scene, e) << " " << e.light << " REJECTED "
          << light_rejection_name(e.rejected) << "  wi " << fmt3(e.wi) << "  pdf " << fmt(e.pdf) << "  Le "
          << fmt3(e.Le) << "  (no shadow ray, nothing added)\n";
      return;
    }
    out << "#" << e.vertex << " light    " << light_kind(scene, e) << " " << e.light;
    if (!e.infinite) out << "  point " << fmt3(e.point) << "  dist " << fmt(e.dist);
    out << "  wi " << fmt3(e.wi) << "  pdf " << fmt(e.pdf) << "  Le " << fmt3(e.Le)
        << (e.visible ? "  visible" : "  occluded") << "  mis " << fmt(e.mis_weight) << "  added " << fmt3(e.added)
        << "\n";
  }
  void operator()(const ScatterEvent& e) const {
    out << "#" << e.vertex << " scatter  " << (e.cosine ? "cosine" : lobe_name(e.lobe)) << (e.impulse ? " (impulse)" : "")
        << "  wi " << fmt3(e.wi) << "  pdf " << fmt(e.pdf) << "  weight " << fmt3(e.weight);
    if (e.survival < 1.0f) out << "  roulette p " << fmt(e.survival);
    out << "  throughput " << fmt3(e.throughput) << "\n";
  }
  void operator()(const EndEvent& e) const {
    out << "#" << e.vertex << " end      " << path_end_name(e.reason) << "\n";
  }
};

}  // namespace

Spectrum film_radiance(const TraceHeader& h, const PathRecorder& path) {
  return clamp_radiance(path.result(), h.settings.clamp);
}

json path_to_json(const TraceHeader& h, const PathRecorder& path, const Scene& scene) {
  json events = json::array();
  for (const PathEvent& e : path.events()) events.push_back(std::visit(JsonVisitor{scene}, e));
  const RenderSettings& r = h.settings;
  const Spectrum film = film_radiance(h, path);
  return {{"format", "pathlab-trace"},
          {"version", 1},
          {"scene", h.scene},
          {"tracer", h.tracer},
          {"resolution", {h.width, h.height}},
          {"pixel", {h.x, h.y}},
          {"sample", h.sample},
          {"seed", r.seed},
          {"strategy", strategy_name(r.strategy)},
          {"sampler", sampler_name(r.sampler)},
          {"spp", r.spp},
          {"max_depth", r.max_depth},
          {"rr_depth", r.rr_depth},
          {"bsdf_sampling", bsdf_sampling_name(r.bsdf_sampling)},
          {"clamp", r.clamp},
          {"min_pdf", r.min_pdf},
          {"general_shading", r.force_general_shading},
          {"texture_filter", texture_filter_name(r.texture_filter)},
          {"bvh", r.compact_bvh ? "compact" : "fast"},
          {"pathlab_version", PATHLAB_VERSION},
          {"git_revision", git_revision()},
          {"command_line", h.command_line.empty() ? json(nullptr) : json(h.command_line)},
          {"events", events},
          {"radiance", j3(path.result())},
          {"film_radiance", j3(film)},
          {"clamped", film != path.result()}};
}

std::string event_to_text(const PathEvent& event, const Scene& scene) {
  std::ostringstream out;
  std::visit(TextVisitor{scene, out}, event);
  return out.str();
}

std::string trace_header_text(const TraceHeader& h) {
  std::ostringstream out;
  out << h.scene << "  " << h.width << "x" << h.height << "  pixel (" << h.x << ", " << h.y << ")  sample " << h.sample << "  seed " << h.settings.seed
      << "  tracer " << h.tracer << "  strategy " << strategy_name(h.settings.strategy) << "  max depth "
      << h.settings.max_depth << "  rr depth " << h.settings.rr_depth << "\n";
  // Every other setting that changes a sample (core/render.h), and the build.
  out << "settings   ";
  for (const auto& [key, value] : sample_settings(h.settings)) {
    if (key == "strategy" || key == "seed" || key == "max_depth" || key == "rr_depth") continue;
    out << " " << key << " " << value;
  }
  out << "\npathlab " << PATHLAB_VERSION << " (git " << git_revision() << ")";
  if (!h.command_line.empty()) out << "  command: " << h.command_line;
  out << "\n";
  return out.str();
}

// The radiance line, and what the film receives when the clamp changed it.
std::string result_text(const TraceHeader& h, const PathRecorder& path, const char* who) {
  const Spectrum film = film_radiance(h, path);
  std::string text = std::string(who) + "radiance    " + fmt3(path.result()) + "\n";
  if (film != path.result())
    text += std::string(who) + "film        " + fmt3(film) + "  (clamped to " + fmt(h.settings.clamp) +
            ": what the film receives)\n";
  return text;
}

std::string path_to_text(const TraceHeader& h, const PathRecorder& path, const Scene& scene) {
  std::ostringstream out;
  out << trace_header_text(h);
  for (const PathEvent& e : path.events()) out << event_to_text(e, scene);
  out << result_text(h, path, "");
  return out.str();
}

}  // namespace pathlab
