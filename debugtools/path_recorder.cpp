#include "debugtools/path_recorder.h"

#include "core/error.h"
#include "core/json_number.h"
#include "core/light_sampler.h"
#include "core/render.h"

#include <array>
#include <cstdio>
#include <sstream>

namespace pathlab {
namespace {

using json = nlohmann::json;

json j3(const vec3& v) { return json::array({v.x, v.y, v.z}); }

// A ray as {origin, dir, tmax}; an unbounded one's tmax is null.
json jray(const Ray& r) {
  return {{"origin", j3(r.origin)}, {"dir", j3(r.dir)}, {"tmax", std::isinf(r.tmax) ? json(nullptr) : json(r.tmax)}};
}

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
    j["ray"] = e.rejected == LightRejection::None ? jray(e.ray) : json(nullptr);  // the shadow ray
    return j;
  }
  json operator()(const ScatterEvent& e) const {
    return {{"type", "scatter"}, {"vertex", e.vertex}, {"lobe", e.cosine ? "cosine" : lobe_name(e.lobe)},
            {"impulse", e.impulse}, {"wi", j3(e.wi)}, {"pdf", e.pdf},
            {"weight", j3(e.weight)}, {"survival", e.survival}, {"throughput", j3(e.throughput)},
            {"next", jray(e.next)}};  // the continuation ray
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
          {"light_sampling", light_sampling_name(r.light_sampling)},
          {"light_sampler", light_sampler_name(r.light_sampler)},
          {"clamp", r.clamp},
          {"min_pdf", r.min_pdf},
          {"general_shading", r.force_general_shading},
          {"texture_filter", texture_filter_name(r.texture_filter)},
          {"intersection", intersection_name(r.intersection)},
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

// --- trace-pixel --json back into events -----------------------------------

namespace {
struct JsonEvents {
  const Scene& scene;
  const std::string& what;
  std::uint32_t pixel_x = 0, pixel_y = 0, sample = 0;  // from the document's header
  std::size_t index = 0;

  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(what + ": events[" + std::to_string(index) + "]: " + problem);
  }
  const nlohmann::json& field(const nlohmann::json& e, const char* key) const {
    if (!e.contains(key)) fail(std::string("no \"") + key + "\"");
    return e.at(key);
  }
  float num(const nlohmann::json& e, const char* key) const {
    const nlohmann::json& v = field(e, key);
    if (v.is_null()) return std::numeric_limits<float>::infinity();
    const std::optional<float> f = json_float(v);
    if (!f) fail(std::string("\"") + key + "\" is " + v.dump() + ", not a number a float holds");
    return *f;
  }
  int integer(const nlohmann::json& e, const char* key) const {
    const nlohmann::json& v = field(e, key);
    const std::optional<int> i = json_integer<int>(v);
    if (!i) fail(std::string("\"") + key + "\" is " + v.dump() + ", not an integer an int holds");
    return *i;
  }
  bool flag(const nlohmann::json& e, const char* key) const {
    const nlohmann::json& v = field(e, key);
    if (!v.is_boolean()) fail(std::string("\"") + key + "\" is not true or false");
    return v.get<bool>();
  }
  // v as N numbers floats hold: nothing if it is not an array of N or one of
  // them is not such a number.
  template <std::size_t N>
  static std::optional<std::array<float, N>> floats(const nlohmann::json& v) {
    if (!v.is_array() || v.size() != N) return std::nullopt;
    std::array<float, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
      const std::optional<float> f = json_float(v[i]);
      if (!f) return std::nullopt;
      out[i] = *f;
    }
    return out;
  }
  vec3 v3(const nlohmann::json& e, const char* key) const {
    const nlohmann::json& v = field(e, key);
    if (!v.is_array() || v.size() != 3) fail(std::string("\"") + key + "\" is not [x, y, z]");
    const std::optional<std::array<float, 3>> f = floats<3>(v);
    if (!f) fail(std::string("\"") + key + "\" is " + v.dump() + ", not three numbers floats hold");
    return vec3((*f)[0], (*f)[1], (*f)[2]);
  }
  // A ray {origin, dir, tmax (null: unbounded)}; absent (a trace by a build
  // older than the field) or null (a light sample with no shadow ray): a
  // zero ray.
  Ray ray(const nlohmann::json& e, const char* key) const {
    if (!e.contains(key) || e.at(key).is_null()) return Ray{};
    const nlohmann::json& r = e.at(key);
    if (!r.is_object()) fail(std::string("\"") + key + "\" is not {origin, dir, tmax}");
    return Ray{v3(r, "origin"), v3(r, "dir"), num(r, "tmax")};
  }
  std::string text(const nlohmann::json& e, const char* key) const {
    const nlohmann::json& v = field(e, key);
    if (!v.is_string()) fail(std::string("\"") + key + "\" is not a string");
    return v.get<std::string>();
  }

  PathEvent event(const nlohmann::json& e) const {
    const std::string type = text(e, "type");
    if (type == "camera") {
      const nlohmann::json& f = field(e, "film");
      const std::optional<std::array<float, 2>> film = floats<2>(f);
      if (!film) fail("\"film\" is not [x, y] (two numbers floats hold)");
      CameraEvent c;
      c.x = pixel_x;
      c.y = pixel_y;
      c.sample = sample;
      c.film = vec2((*film)[0], (*film)[1]);
      c.origin = v3(e, "origin");
      c.dir = v3(e, "dir");
      return c;
    }
    if (type == "hit") {
      HitEvent h;
      h.vertex = integer(e, "vertex");
      h.p = v3(e, "p");
      h.n = v3(e, "n");
      h.front = flag(e, "front");
      const std::string material = text(e, "material");
      h.material = static_cast<std::uint32_t>(scene.materials.size());  // unknown names stay apart
      for (std::size_t m = 0; m < scene.materials.size(); ++m)
        if (scene.materials[m].name == material) h.material = static_cast<std::uint32_t>(m);
      h.shape = static_cast<std::uint32_t>(integer(e, "shape"));
      h.prim = static_cast<std::uint32_t>(integer(e, "prim"));
      const nlohmann::json& inst = field(e, "instance");
      const std::optional<std::uint32_t> instance =
          inst.is_null() ? std::optional<std::uint32_t>(kNoInstance) : json_integer<std::uint32_t>(inst);
      if (!instance) fail("\"instance\" is " + inst.dump() + ", not null or an instance's number");
      h.instance = *instance;
      h.emitted = v3(e, "emitted");
      h.emission_weight = num(e, "emission_weight");
      h.added = v3(e, "added");
      h.throughput = v3(e, "throughput");
      return h;
    }
    if (type == "escape") {
      EscapeEvent x;
      x.vertex = integer(e, "vertex");
      x.emitted = v3(e, "emitted");
      x.emission_weight = num(e, "emission_weight");
      x.added = v3(e, "added");
      return x;
    }
    if (type == "light") {
      LightEvent l;
      l.vertex = integer(e, "vertex");
      const std::string kind = text(e, "kind");
      l.delta = kind != "area" && kind != "environment";
      l.infinite = kind == "environment";
      // A light sample the sampler did not give (rejected "no_sample") names no light.
      l.light = field(e, "light").is_null() ? 0u : static_cast<std::uint32_t>(integer(e, "light"));
      // "rejected" is absent from the traces of builds older than it.
      const nlohmann::json rejected = e.contains("rejected") ? e["rejected"] : nlohmann::json(nullptr);
      if (!rejected.is_null()) {
        bool known = false;
        for (LightRejection r : {LightRejection::NoSample, LightRejection::BelowSurface, LightRejection::BlackBsdf})
          if (rejected.is_string() && rejected.get<std::string>() == light_rejection_name(r)) l.rejected = r, known = true;
        if (!known) fail("unknown light rejection " + rejected.dump());
      }
      l.point = v3(e, "point");
      l.wi = v3(e, "wi");
      l.pdf = num(e, "pdf");
      l.Le = v3(e, "Le");
      l.visible = flag(e, "visible");
      l.mis_weight = num(e, "mis_weight");
      l.added = v3(e, "added");
      l.dist = num(e, "dist");
      l.ray = ray(e, "ray");
      return l;
    }
    if (type == "scatter") {
      ScatterEvent s;
      s.vertex = integer(e, "vertex");
      const std::string lobe = text(e, "lobe");
      s.cosine = lobe == "cosine";
      bool known = s.cosine;
      for (int k = 0; k < static_cast<int>(Lobe::Count); ++k)
        if (lobe == lobe_name(static_cast<Lobe>(k))) s.lobe = static_cast<Lobe>(k), known = true;
      if (!known) fail("unknown lobe \"" + lobe + "\"");
      s.impulse = flag(e, "impulse");
      s.wi = v3(e, "wi");
      s.pdf = num(e, "pdf");
      s.weight = v3(e, "weight");
      s.survival = num(e, "survival");
      s.throughput = v3(e, "throughput");
      s.next = ray(e, "next");
      return s;
    }
    if (type == "end") {
      EndEvent x;
      x.vertex = integer(e, "vertex");
      const std::string reason = text(e, "reason");
      bool known = false;
      for (PathEnd p : {PathEnd::Escaped, PathEnd::MaxDepth, PathEnd::Absorbed, PathEnd::Roulette, PathEnd::NoSample})
        if (reason == path_end_name(p)) x.reason = p, known = true;
      if (!known) fail("unknown end \"" + reason + "\"");
      return x;
    }
    fail("unknown event type \"" + type + "\"");
  }
};
}  // namespace

bool trace_records_rays(const nlohmann::json& doc) {
  if (!doc.is_object() || !doc.contains("events") || !doc.at("events").is_array()) return false;
  for (const nlohmann::json& e : doc.at("events"))
    if (e.is_object() && (e.contains("ray") || e.contains("next"))) return true;
  return false;
}

void forget_rays(std::vector<PathEvent>& events) {
  for (PathEvent& e : events) {
    if (auto* l = std::get_if<LightEvent>(&e)) l->ray = Ray{};
    if (auto* s = std::get_if<ScatterEvent>(&e)) s->next = Ray{};
  }
}

std::vector<PathEvent> path_events_from_json(const nlohmann::json& doc, const Scene& scene, const std::string& what) {
  if (!doc.is_object() || doc.value("format", "") != "pathlab-trace" || !doc.contains("events") ||
      !doc.at("events").is_array())
    throw InputError(what + ": not a `pathlab trace-pixel --json` document (format \"pathlab-trace\")");
  JsonEvents parse{scene, what};
  const auto header_int = [&](const nlohmann::json& v, const char* key) {
    const std::optional<std::uint32_t> n = json_integer<std::uint32_t>(v);
    if (!n) throw InputError(what + ": \"" + key + "\" is " + v.dump() + ", not an integer from 0 to 4294967295");
    return *n;
  };
  if (doc.contains("pixel")) {
    const nlohmann::json& px = doc.at("pixel");
    if (!px.is_array() || px.size() != 2) throw InputError(what + ": \"pixel\" is not [x, y]");
    parse.pixel_x = header_int(px[0], "pixel");
    parse.pixel_y = header_int(px[1], "pixel");
  }
  if (doc.contains("sample")) parse.sample = header_int(doc.at("sample"), "sample");
  std::vector<PathEvent> events;
  try {
    for (const nlohmann::json& e : doc.at("events")) {
      if (!e.is_object()) parse.fail("not an object");
      events.push_back(parse.event(e));
      ++parse.index;
    }
  } catch (const nlohmann::json::exception& ex) {
    throw InputError(what + ": events[" + std::to_string(parse.index) + "]: " + ex.what());
  }
  return events;
}

}  // namespace pathlab
