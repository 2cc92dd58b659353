// Replaying one pixel sample: deterministic, identical to the render, and
// reachable from the command a NaN report prints.
#include "apps/cli/cli.h"
#include "apps/cli/scene_options.h"
#include "core/compiled_scene.h"
#include "core/render.h"
#include "debugtools/path_compare.h"
#include "debugtools/path_recorder.h"
#include "reference/reference_tracer.h"
#include "tests/test_scenes.h"
#include "core/scene_loader.h"
#include "debugtools/path_geometry.h"
#include "debugtools/tracers.h"

#include <gtest/gtest.h>

#include <cstring>
#include <sstream>

namespace pathlab {
namespace {

TEST(TracePixel, ReplayIsDeterministicAndMatchesTheRender) {
  Scene scene = test::small_cornell(16, 3, FilterKind::Box);
  scene.render.strategy = Strategy::Mis;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  std::vector<FilmSample> batch(16 * 16 * 3);
  tracer.render_batch(0, 3, batch);

  for (std::uint32_t sample = 0; sample < 3; ++sample) {
    PathRecorder a, b;
    const FilmSample fa = tracer.trace_sample(7, 9, sample, &a);
    tracer.trace_sample(7, 9, sample, &b);
    const TraceHeader h{"cornell", "reference", 7, 9, sample, settings, 16, 16};
    EXPECT_EQ(path_to_json(h, a, compiled.scene()).dump(), path_to_json(h, b, compiled.scene()).dump());
    // The observer changes nothing: same bits as the production render.
    const FilmSample& fr = batch[(9 * 16 + 7) * 3 + sample];
    EXPECT_EQ(std::memcmp(&fa.L, &fr.L, sizeof(Spectrum)), 0);
    EXPECT_EQ(fa.film, fr.film);
    EXPECT_EQ(a.result(), fa.L);
  }
}

TEST(TracePixel, EventsAddUpToTheRadiance) {
  Scene scene = test::small_cornell(16, 1, FilterKind::Box);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  int paths_with_light = 0;
  for (std::uint32_t sample = 0; sample < 64; ++sample) {
    PathRecorder rec;
    const FilmSample fs = tracer.trace_sample(8, 12, sample, &rec);
    Spectrum sum(0.0f);
    for (const PathEvent& e : rec.events()) {
      if (const auto* h = std::get_if<HitEvent>(&e)) sum += h->added;
      if (const auto* l = std::get_if<LightEvent>(&e)) sum += l->added;
      if (const auto* x = std::get_if<EscapeEvent>(&e)) sum += x->added;
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], fs.L[c], 1e-4f * (1.0f + fs.L[c]));
    ASSERT_FALSE(rec.events().empty());
    EXPECT_TRUE(std::holds_alternative<CameraEvent>(rec.events().front()));
    EXPECT_TRUE(std::holds_alternative<EndEvent>(rec.events().back()));
    paths_with_light += max_component(fs.L) > 0.0f;
  }
  EXPECT_GT(paths_with_light, 0);
}

TEST(TracePixel, CliJsonIsStable) {
  const char* argv[] = {"pathlab", "trace-pixel", "--pixel", "20,30", "--sample", "2", "--resolution", "64x64", "--json"};
  std::ostringstream out1, err1, out2, err2;
  ASSERT_EQ(cli::run(static_cast<int>(std::size(argv)), argv, out1, err1), 0) << err1.str();
  ASSERT_EQ(cli::run(static_cast<int>(std::size(argv)), argv, out2, err2), 0) << err2.str();
  EXPECT_EQ(out1.str(), out2.str());
  const auto j = nlohmann::json::parse(out1.str());
  EXPECT_EQ(j["format"], "pathlab-trace");
  EXPECT_EQ(j["version"], 1);
  EXPECT_EQ(j["pixel"], nlohmann::json::array({20, 30}));
  EXPECT_EQ(j["sample"], 2);
  EXPECT_EQ(j["events"].front()["type"], "camera");
  EXPECT_EQ(j["events"].back()["type"], "end");
  EXPECT_EQ(j["radiance"].size(), 3u);
}

TEST(TracePixel, BothTracersSideBySideAgree) {
  for (const char* sample : {"0", "1", "2", "3"}) {
    const char* argv[] = {"pathlab", "trace-pixel", "--pixel", "20,30", "--sample", sample, "--resolution", "64x64",
                          "--tracer", "both", "--json"};
    std::ostringstream out, err;
    ASSERT_EQ(cli::run(static_cast<int>(std::size(argv)), argv, out, err), 0) << err.str();
    const auto j = nlohmann::json::parse(out.str());
    EXPECT_EQ(j["format"], "pathlab-trace-pair");
    EXPECT_EQ(j["reference"]["tracer"], "reference");
    EXPECT_EQ(j["wavefront"]["tracer"], "wavefront");
    EXPECT_TRUE(j["divergence"].is_null()) << j["divergence"].dump();
    EXPECT_EQ(j["reference"]["events"].size(), j["wavefront"]["events"].size());
  }
  // The text form marks agreement (or the parting vertex) for a person.
  const char* argv[] = {"pathlab", "trace-pixel", "--pixel", "20,30", "--resolution", "64x64", "--tracer", "both"};
  std::ostringstream out, err;
  ASSERT_EQ(cli::run(static_cast<int>(std::size(argv)), argv, out, err), 0);
  EXPECT_NE(err.str().find("the paths agree at every event"), std::string::npos) << err.str();
}

TEST(TracePixel, FirstDivergenceTellsRoundingFromADifferentPath) {
  Scene scene = test::small_cornell(16, 1, FilterKind::Box);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  PathRecorder rec;
  tracer.trace_sample(8, 10, 0, &rec);
  const std::vector<PathEvent>& a = rec.events();
  EXPECT_TRUE(first_divergence(a, a, 1e-4f).identical);

  std::vector<PathEvent> b = a;  // a visibility flipped by rounding
  for (PathEvent& e : b)
    if (auto* l = std::get_if<LightEvent>(&e)) {
      l->visible = !l->visible;
      break;
    }
  PathDivergence d = first_divergence(a, b, 1e-4f);
  EXPECT_FALSE(d.identical);
  EXPECT_TRUE(d.rounding) << d.reason;
  EXPECT_NE(d.reason.find("visibility"), std::string::npos) << d.reason;

  b = a;  // a different camera ray: another path, not rounding
  std::get<CameraEvent>(b[0]).dir = -std::get<CameraEvent>(b[0]).dir;
  d = first_divergence(a, b, 1e-4f);
  EXPECT_FALSE(d.rounding) << d.reason;
  EXPECT_EQ(d.event, 0u);
}

// A tracer that fails on one sample, to exercise the NaN report.
class NanAtOneSample final : public Tracer {
 public:
  using Tracer::Tracer;
  std::string_view name() const override { return "nan-test"; }
  FilmSample trace_sample(std::uint32_t x, std::uint32_t y, std::uint32_t sample, PathObserver*) const override {
    FilmSample fs{vec2(float(x) + 0.5f, float(y) + 0.5f), Spectrum(1.0f), 1};
    if (x == 3 && y == 2 && sample == 5) fs.L.y = std::nanf("");
    return fs;
  }
  void render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const override {
    const int w = scene_.scene().film.width;
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = trace_sample(static_cast<std::uint32_t>((i / count) % w), static_cast<std::uint32_t>((i / count) / w),
                            first + static_cast<std::uint32_t>(i % count), nullptr);
  }
};

TEST(TracePixel, NanIsKeptOutOfTheImageAndReportedWithItsReplayCommand) {
  Scene scene = test::small_cornell(8, 8, FilterKind::Bilinear);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const NanAtOneSample tracer(compiled, settings);
  Film film(8, 8, FilterKind::Bilinear);
  const RenderStats stats = render(tracer, film);
  EXPECT_EQ(stats.bad_samples, 1u);
  for (const vec3& p : film.image().pixels) EXPECT_EQ(p, vec3(1.0f));
  ASSERT_EQ(film.bad_samples().size(), 1u);
  const BadSample& b = film.bad_samples()[0];
  EXPECT_EQ(b.x, 3u);
  EXPECT_EQ(b.y, 2u);
  EXPECT_EQ(b.sample, 5u);

  // The printed command replays exactly that sample.
  cli::SceneOptions options;
  const std::string cmd = options.trace_pixel_command(compiled.scene(), b.x, b.y, b.sample);
  EXPECT_NE(cmd.find("--pixel 3,2 --sample 5"), std::string::npos) << cmd;
  std::istringstream words(cmd);
  std::vector<std::string> args((std::istream_iterator<std::string>(words)), std::istream_iterator<std::string>());
  args.push_back("--json");
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  ASSERT_EQ(cli::run(static_cast<int>(argv.size()), argv.data(), out, err), 0) << err.str();
  const auto j = nlohmann::json::parse(out.str());
  EXPECT_EQ(j["pixel"], nlohmann::json::array({3, 2}));
  EXPECT_EQ(j["sample"], 5);
}


// A floor lit by a point light; `below` puts it under the floor, `mirror`
// makes the floor a mirror. Both tracers replay pixel (12,12) sample 0.
Scene floor_with_point_light(bool below, bool mirror) {
  const std::string text = std::string(R"({
    "pathlab_scene": 1,
    "camera": {"position": [0, 6, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov_y": 90},
    "film": {"resolution": [24, 24]},
    "render": {"spp": 1, "max_depth": 1, "strategy": "light"},
    "materials": {"floor": )") + (mirror ? R"({"type": "mirror"})" : R"({"type": "diffuse", "albedo": 0.5})") + R"(},
    "shapes": [{"type": "rectangle", "material": "floor",
                "transform": [{"rotate": {"axis": [1, 0, 0], "angle": -90}}, {"scale": 10}]}],
    "lights": [{"type": "point", "position": [0, )" + (below ? "-2" : "2") + R"(, 0], "intensity": 1}]})";
  return parse_scene(text, "floor.json");
}

// A light sample dropped before its shadow ray is an event with its reason,
// in both tracers alike, in the JSON and the text.
TEST(TracePixel, RejectedLightSamplesAreReportedByBothTracers) {
  struct Case {
    bool below, mirror;
    LightRejection want;
    const char* name;
  };
  for (const Case& c : {Case{true, false, LightRejection::BelowSurface, "below_surface"},
                        Case{false, true, LightRejection::BlackBsdf, "black_bsdf"},
                        Case{false, false, LightRejection::None, ""}}) {
    Scene scene = floor_with_point_light(c.below, c.mirror);
    const RenderSettings settings = scene.render;
    const CompiledScene compiled(std::move(scene));
    PathRecorder ref, wave;
    make_tracer("reference", compiled, settings)->trace_sample(12, 12, 0, &ref);
    make_tracer("wavefront", compiled, settings)->trace_sample(12, 12, 0, &wave);
    const auto light_events = [](const PathRecorder& r) {
      std::vector<LightEvent> out;
      for (const PathEvent& e : r.events())
        if (const auto* l = std::get_if<LightEvent>(&e)) out.push_back(*l);
      return out;
    };
    const std::vector<LightEvent> lr = light_events(ref), lw = light_events(wave);
    ASSERT_EQ(lr.size(), 1u) << c.name << ": the reference reports no light event";
    ASSERT_EQ(lw.size(), 1u) << c.name << ": the wavefront reports no light event";
    EXPECT_EQ(lr[0].rejected, c.want) << c.name;
    EXPECT_EQ(lw[0].rejected, c.want) << c.name;
    EXPECT_TRUE(first_divergence(ref.events(), wave.events(), 1e-4f).identical) << c.name;
    if (c.want == LightRejection::None) {
      EXPECT_TRUE(lr[0].visible);
      continue;
    }
    EXPECT_FALSE(lr[0].visible);
    EXPECT_EQ(lr[0].added, Spectrum(0.0f));
    EXPECT_TRUE(lr[0].delta);
    EXPECT_EQ(lr[0].wi.y < 0.0f, c.below) << "the light is where it was put";
    const TraceHeader h{"floor", "reference", 12, 12, 0, settings, 24, 24};
    const nlohmann::json j = path_to_json(h, ref, compiled.scene());
    bool found = false;
    for (const auto& e : j["events"])
      if (e["type"] == "light") {
        EXPECT_EQ(e["rejected"], c.name);
        found = true;
      }
    EXPECT_TRUE(found);
    const std::string text = path_to_text(h, wave, compiled.scene());
    EXPECT_NE(text.find(std::string("point 0 REJECTED ") + c.name), std::string::npos) << text;
    // A rejected sample traced no shadow ray: none is drawn.
    for (const PathLine& l : path_lines(ref, 0, 10.0f)) EXPECT_NE(l.kind, PathLine::Kind::Shadow) << c.name;
  }
}

}  // namespace
}  // namespace pathlab
