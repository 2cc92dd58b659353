// first_divergence compares every field of every event kind (label "unit"):
// for each field, two event lists that differ in exactly that field are
// reported at that event, with that field named in the reason.
#include "core/error.h"
#include "debugtools/path_compare.h"
#include "debugtools/path_recorder.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace pathlab {
namespace {

// A path with one event of every kind, every field set to a distinct,
// non-default value.
std::vector<PathEvent> full_path() {
  CameraEvent cam;
  cam.x = 3;
  cam.y = 4;
  cam.sample = 5;
  cam.film = vec2(3.25f, 4.75f);
  cam.origin = vec3(0.1f, 0.2f, 0.3f);
  cam.dir = glm::normalize(vec3(0.1f, -0.2f, -1.0f));
  HitEvent hit;
  hit.vertex = 1;
  hit.p = vec3(1.0f, 2.0f, 3.0f);
  hit.n = vec3(0.0f, 1.0f, 0.0f);
  hit.front = true;
  hit.material = 2;
  hit.shape = 3;
  hit.prim = 7;
  hit.instance = 1;
  hit.emitted = Spectrum(0.5f, 0.25f, 0.125f);
  hit.emission_weight = 0.6f;
  hit.added = Spectrum(0.3f, 0.15f, 0.075f);
  hit.throughput = Spectrum(0.9f, 0.8f, 0.7f);
  LightEvent light;
  light.vertex = 1;
  light.delta = false;
  light.infinite = false;
  light.light = 4;
  light.point = vec3(0.0f, 5.0f, 0.0f);
  light.wi = glm::normalize(vec3(-1.0f, 3.0f, -3.0f));
  light.dist = 4.4f;
  light.pdf = 0.7f;
  light.Le = Spectrum(10.0f, 9.0f, 8.0f);
  light.visible = true;
  light.mis_weight = 0.4f;
  light.added = Spectrum(0.2f, 0.3f, 0.4f);
  light.ray = Ray{vec3(1.0f, 2.0f, 3.0f), light.wi, 4.3f};
  ScatterEvent sc;
  sc.vertex = 1;
  sc.lobe = Lobe::Specular;
  sc.impulse = false;
  sc.cosine = false;
  sc.wi = glm::normalize(vec3(0.3f, 0.5f, 0.2f));
  sc.pdf = 1.7f;
  sc.weight = Spectrum(0.7f, 0.6f, 0.5f);
  sc.survival = 0.8f;
  sc.throughput = Spectrum(0.6f, 0.5f, 0.4f);
  sc.next = Ray{vec3(1.0f, 2.0f, 3.0f), sc.wi, 1e30f};
  EscapeEvent esc;
  esc.vertex = 2;
  esc.emitted = Spectrum(0.1f, 0.2f, 0.3f);
  esc.emission_weight = 0.5f;
  esc.added = Spectrum(0.03f, 0.05f, 0.06f);
  EndEvent end;
  end.vertex = 2;
  end.reason = PathEnd::Escaped;
  return {cam, hit, light, sc, esc, end};
}

struct FieldCase {
  std::size_t event;
  const char* field;  // as the reason must name it
  std::function<void(PathEvent&)> change;
};

template <class T>
std::function<void(PathEvent&)> on(std::function<void(T&)> f) {
  return [f](PathEvent& e) { f(std::get<T>(e)); };
}

std::vector<FieldCase> cases() {
  const float big = 0.5f;  // far beyond the tolerance, relative and absolute
  return {
      {0, "pixel x, y", on<CameraEvent>([](CameraEvent& e) { e.x += 1; })},
      {0, "pixel x, y", on<CameraEvent>([](CameraEvent& e) { e.y += 1; })},
      {0, "sample", on<CameraEvent>([](CameraEvent& e) { e.sample += 1; })},
      {0, "film", on<CameraEvent>([=](CameraEvent& e) { e.film.x += big; })},
      {0, "origin", on<CameraEvent>([=](CameraEvent& e) { e.origin.y += big; })},
      {0, "dir", on<CameraEvent>([=](CameraEvent& e) { e.dir.z += big; })},
      {1, "shape", on<HitEvent>([](HitEvent& e) { e.shape += 1; })},
      {1, "prim", on<HitEvent>([](HitEvent& e) { e.prim += 1; })},
      {1, "instance", on<HitEvent>([](HitEvent& e) { e.instance = kNoInstance; })},
      {1, "material", on<HitEvent>([](HitEvent& e) { e.material += 1; })},
      {1, "front", on<HitEvent>([](HitEvent& e) { e.front = !e.front; })},
      {1, "(p)", on<HitEvent>([=](HitEvent& e) { e.p.x += 3.0f * big; })},
      {1, "(n)", on<HitEvent>([=](HitEvent& e) { e.n.x += big; })},
      {1, "throughput", on<HitEvent>([=](HitEvent& e) { e.throughput.y += big; })},
      {1, "emitted", on<HitEvent>([=](HitEvent& e) { e.emitted.z += big; })},
      {1, "emission_weight", on<HitEvent>([=](HitEvent& e) { e.emission_weight += big; })},
      {1, "added", on<HitEvent>([=](HitEvent& e) { e.added.x += big; })},
      {2, "delta", on<LightEvent>([](LightEvent& e) { e.delta = !e.delta; })},
      {2, "infinite", on<LightEvent>([](LightEvent& e) { e.infinite = !e.infinite; })},
      {2, "(light)", on<LightEvent>([](LightEvent& e) { e.light += 1; })},
      {2, "point", on<LightEvent>([=](LightEvent& e) { e.point.x += big; })},
      {2, "(wi)", on<LightEvent>([=](LightEvent& e) { e.wi.x += big; })},
      {2, "dist", on<LightEvent>([=](LightEvent& e) { e.dist += 3.0f * big; })},
      {2, "(pdf)", on<LightEvent>([=](LightEvent& e) { e.pdf += big; })},
      {2, "Le", on<LightEvent>([=](LightEvent& e) { e.Le.y += 10.0f * big; })},
      {2, "(ray)", on<LightEvent>([=](LightEvent& e) { e.ray.tmax += 3.0f * big; })},
      {2, "(ray)", on<LightEvent>([=](LightEvent& e) { e.ray.origin.z += big; })},
      {2, "visible", on<LightEvent>([](LightEvent& e) { e.visible = !e.visible; })},
      {2, "rejected", on<LightEvent>([](LightEvent& e) { e.rejected = LightRejection::BelowSurface; })},
      {2, "mis_weight", on<LightEvent>([=](LightEvent& e) { e.mis_weight += big; })},
      {2, "(added)", on<LightEvent>([=](LightEvent& e) { e.added.z += big; })},
      {3, "(lobe)", on<ScatterEvent>([](ScatterEvent& e) { e.lobe = Lobe::Clearcoat; })},
      {3, "impulse", on<ScatterEvent>([](ScatterEvent& e) { e.impulse = !e.impulse; })},
      {3, "cosine", on<ScatterEvent>([](ScatterEvent& e) { e.cosine = !e.cosine; })},
      {3, "(wi)", on<ScatterEvent>([=](ScatterEvent& e) { e.wi.y += big; })},
      {3, "(pdf)", on<ScatterEvent>([=](ScatterEvent& e) { e.pdf += 2.0f * big; })},
      {3, "(weight)", on<ScatterEvent>([=](ScatterEvent& e) { e.weight.x += big; })},
      {3, "survival", on<ScatterEvent>([=](ScatterEvent& e) { e.survival -= big; })},
      {3, "throughput", on<ScatterEvent>([=](ScatterEvent& e) { e.throughput.z += big; })},
      {3, "(next)", on<ScatterEvent>([=](ScatterEvent& e) { e.next.dir.x += big; })},
      {4, "emitted", on<EscapeEvent>([=](EscapeEvent& e) { e.emitted.x += big; })},
      {4, "emission_weight", on<EscapeEvent>([=](EscapeEvent& e) { e.emission_weight += big; })},
      {4, "added", on<EscapeEvent>([=](EscapeEvent& e) { e.added.y += big; })},
      {5, "reason", on<EndEvent>([](EndEvent& e) { e.reason = PathEnd::Roulette; })},
  };
}

TEST(PathCompare, EveryFieldOfEveryEventIsComparedAndNamed) {
  const std::vector<PathEvent> a = full_path();
  ASSERT_TRUE(first_divergence(a, a, 1e-4f).identical);
  int n = 0;
  for (const FieldCase& c : cases()) {
    std::vector<PathEvent> b = a;
    c.change(b[c.event]);
    const PathDivergence d = first_divergence(a, b, 1e-4f);
    EXPECT_FALSE(d.identical) << "field " << c.field << " of event " << c.event << " is not compared";
    EXPECT_EQ(d.event, c.event) << c.field << ": " << d.reason;
    EXPECT_NE(d.reason.find(c.field), std::string::npos) << "the reason should name " << c.field << ": " << d.reason;
    // And the same the other way round.
    const PathDivergence r = first_divergence(b, a, 1e-4f);
    EXPECT_FALSE(r.identical) << c.field;
    EXPECT_EQ(r.event, c.event) << c.field;
    ++n;
  }
  EXPECT_EQ(n, 44);
}

// Across builds (`compare --with`) paths are compared as read back from
// `trace-pixel --json`: every field must survive the round trip, so a
// difference in any of them is still found and named.
TEST(PathCompare, EveryFieldSurvivesTheTraceJson) {
  Scene scene;
  for (const char* name : {"m0", "m1", "m2", "m3"}) {
    Material m;
    m.name = name;
    scene.materials.push_back(m);
  }
  const auto round_trip = [&](const std::vector<PathEvent>& events) {
    PathRecorder recorder;
    for (const PathEvent& e : events)
      std::visit(
          [&](const auto& ev) {
            using T = std::decay_t<decltype(ev)>;
            if constexpr (std::is_same_v<T, CameraEvent>) recorder.on_camera(ev);
            else if constexpr (std::is_same_v<T, HitEvent>) recorder.on_hit(ev);
            else if constexpr (std::is_same_v<T, EscapeEvent>) recorder.on_escape(ev);
            else if constexpr (std::is_same_v<T, LightEvent>) recorder.on_light(ev);
            else if constexpr (std::is_same_v<T, ScatterEvent>) recorder.on_scatter(ev);
            else recorder.on_end(ev);
          },
          e);
    const CameraEvent& cam = std::get<CameraEvent>(events.front());
    TraceHeader header{"test", "reference", cam.x, cam.y, cam.sample, RenderSettings{}, 8, 8};
    // Through text, as between two processes.
    const nlohmann::json doc = nlohmann::json::parse(path_to_json(header, recorder, scene).dump());
    EXPECT_TRUE(trace_records_rays(doc));
    return path_events_from_json(doc, scene, "round trip");
  };
  const std::vector<PathEvent> a = full_path();
  const std::vector<PathEvent> a_read = round_trip(a);
  ASSERT_TRUE(first_divergence(a, a_read, 1e-6f).identical) << first_divergence(a, a_read, 1e-6f).reason;
  int n = 0;
  for (const FieldCase& c : cases()) {
    std::vector<PathEvent> b = a;
    c.change(b[c.event]);
    const PathDivergence d = first_divergence(a_read, round_trip(b), 1e-4f);
    EXPECT_FALSE(d.identical) << "field " << c.field << " of event " << c.event << " is lost in the JSON";
    EXPECT_EQ(d.event, c.event) << c.field << ": " << d.reason;
    EXPECT_NE(d.reason.find(c.field), std::string::npos) << "the reason should name " << c.field << ": " << d.reason;
    ++n;
  }
  EXPECT_EQ(n, 44);
  // A trace without the rays (an older build) reads with zero rays, as
  // forget_rays() leaves the other side.
  PathRecorder recorder;
  nlohmann::json old_doc =
      path_to_json(TraceHeader{"test", "reference", 3, 4, 5, RenderSettings{}, 8, 8}, recorder, scene);
  old_doc["events"] = nlohmann::json::array({{{"type", "end"}, {"vertex", 1}, {"reason", "escaped"}}});
  EXPECT_FALSE(trace_records_rays(old_doc));
  std::vector<PathEvent> forgotten = a_read;
  forget_rays(forgotten);
  EXPECT_EQ(std::get<LightEvent>(forgotten[2]).ray.tmax, Ray{}.tmax);
  EXPECT_EQ(std::get<ScatterEvent>(forgotten[3]).next.dir, Ray{}.dir);
}

// A trace from another build is input: numbers no float or integer of its
// field holds (2^40 as a vertex, 1e300 as a position, -1 as the pixel) are
// refused naming the event and the key, not converted (undefined behaviour
// for 1e300 as a float, a silent wrap for -1).
TEST(PathCompare, TraceNumbersOutOfTheirTypesRangeAreRefused) {
  Scene scene;
  PathRecorder recorder;
  const nlohmann::json good =
      path_to_json(TraceHeader{"test", "reference", 3, 4, 5, RenderSettings{}, 8, 8}, recorder, scene);
  const auto refusal = [&](const nlohmann::json& doc) -> std::string {
    try {
      path_events_from_json(doc, scene, "their.json");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  nlohmann::json doc = good;
  doc["events"] = nlohmann::json::array({{{"type", "end"}, {"vertex", 1}, {"reason", "escaped"}}});
  EXPECT_EQ(refusal(doc), "");
  doc["events"][0]["vertex"] = std::uint64_t{1} << 40;
  EXPECT_NE(refusal(doc).find("their.json: events[0]: \"vertex\" is 1099511627776, not an integer"),
            std::string::npos) << refusal(doc);
  doc["events"] = nlohmann::json::array(
      {{{"type", "camera"}, {"film", {0.5, 1e300}}, {"origin", {0, 0, 0}}, {"dir", {0, 0, 1}}}});
  EXPECT_NE(refusal(doc).find("events[0]: \"film\" is not [x, y]"), std::string::npos) << refusal(doc);
  doc["events"][0]["film"] = {0.5, 0.5};
  EXPECT_EQ(refusal(doc), "");
  doc["events"][0]["dir"] = {0, -1e39, 1};
  EXPECT_NE(refusal(doc).find("events[0]: \"dir\" is [0,-1e+39,1], not three numbers"), std::string::npos)
      << refusal(doc);
  doc = good;
  doc["pixel"] = {-1, 4};
  EXPECT_NE(refusal(doc).find("their.json: \"pixel\" is -1, not an integer from 0"), std::string::npos)
      << refusal(doc);
}

// Within the tolerance every field agrees; a vertex or kind change is
// reported as such.
TEST(PathCompare, RoundingWithinTheToleranceIsNoDifference) {
  const std::vector<PathEvent> a = full_path();
  std::vector<PathEvent> b = a;
  std::get<HitEvent>(b[1]).p.x *= 1.0f + 1e-6f;
  std::get<LightEvent>(b[2]).pdf *= 1.0f + 1e-6f;
  std::get<ScatterEvent>(b[3]).weight.x *= 1.0f + 1e-6f;
  EXPECT_TRUE(first_divergence(a, b, 1e-4f).identical);
  b = a;
  std::get<ScatterEvent>(b[3]).vertex = 2;
  const PathDivergence d = first_divergence(a, b, 1e-4f);
  EXPECT_EQ(d.event, 3u);
  EXPECT_NE(d.reason.find("different events"), std::string::npos) << d.reason;
  // The point of a light at infinity is undefined: not compared.
  b = a;
  std::get<LightEvent>(b[2]).infinite = true;
  std::vector<PathEvent> c = b;
  std::get<LightEvent>(c[2]).point = vec3(99.0f);
  EXPECT_TRUE(first_divergence(b, c, 1e-4f).identical);
}

// A different kind of event after an agreeing prefix is a floating-point
// flip only where a threshold decision explains it (a hit against an escape,
// an end by roulette or by a sample with no density); a light sample one
// path skips, an end by the depth cap or events past an end are real changes.
TEST(PathCompare, OnlyThresholdDecisionsExplainDifferentEventKinds) {
  const std::vector<PathEvent> a = full_path();  // camera, hit, light, scatter, escape, end
  const auto part = [&](const std::vector<PathEvent>& b) { return first_divergence(a, b, 1e-4f); };
  const auto end_at = [](int vertex, PathEnd reason) { return PathEvent(EndEvent{vertex, reason}); };

  // Next-event estimation skipped at vertex 1: the light sample is missing.
  std::vector<PathEvent> b = a;
  b.erase(b.begin() + 2);
  PathDivergence d = part(b);
  EXPECT_EQ(d.event, 2u);
  EXPECT_FALSE(d.rounding) << d.reason;
  EXPECT_NE(d.reason.find("a light sample at vertex 1 and a scatter at vertex 1"), std::string::npos) << d.reason;

  // Roulette ended the other path at vertex 1 before it scattered.
  b = {a[0], a[1], a[2], end_at(1, PathEnd::Roulette)};
  d = part(b);
  EXPECT_EQ(d.event, 3u);
  EXPECT_TRUE(d.rounding) << d.reason;
  // ... but a depth cap at vertex 1 is not a rounding difference.
  b.back() = end_at(1, PathEnd::MaxDepth);
  EXPECT_FALSE(part(b).rounding);
  // A sampled direction with no density (grazing) ends it: a flip.
  b.back() = end_at(1, PathEnd::NoSample);
  EXPECT_TRUE(part(b).rounding);

  // The continuation ray hits a surface at vertex 2 where the other escaped.
  b = a;
  HitEvent hit = std::get<HitEvent>(a[1]);
  hit.vertex = 2;
  b[4] = hit;
  b.resize(5);
  d = part(b);
  EXPECT_EQ(d.event, 4u);
  EXPECT_TRUE(d.rounding) << d.reason;

  // An event of another vertex is never a flip.
  b = a;
  std::get<EscapeEvent>(b[4]).vertex = 3;
  EXPECT_FALSE(part(b).rounding);
  // Nor are events past an end both paths agree on.
  b = a;
  b.push_back(a[1]);
  d = part(b);
  EXPECT_EQ(d.event, a.size());
  EXPECT_FALSE(d.rounding) << d.reason;
}

}  // namespace
}  // namespace pathlab
