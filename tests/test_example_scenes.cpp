// Every scene shipped in scenes/ loads without a warning but those its data
// earns (below), compiles, and traces samples to a finite radiance in both
// tracers, the same path in each; the benchmark scenes in bench/scenes/
// load. Some read fetched data ("$data/..."), so these run after the
// pathlab_data fixture.
#include "core/compiled_scene.h"
#include "core/scene_loader.h"
#include "reference/reference_tracer.h"
#include "wavefront/wavefront_tracer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string_view>

namespace pathlab {
namespace {

namespace fs = std::filesystem;

TEST(ExampleScenes, LoadCompileAndTrace) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(PATHLAB_SOURCE_DIR) / "scenes")) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    Scene scene = load_scene(entry.path());
    // What the fetched data earns: the webxr controller's occlusion map
    // (glTF's occlusion is not modelled) and the few slightly negative
    // texels of every HDRI Haven map (read as 0).
    for (const std::string& w : scene.warnings)
      EXPECT_TRUE(w.find("ignored (not supported yet): occlusionTexture") != std::string::npos ||
                  w.find("texel component(s) are negative") != std::string::npos)
          << w;
    const RenderSettings settings = scene.render;
    const CompiledScene compiled(std::move(scene));
    const ReferenceTracer reference(compiled, settings);
    const WavefrontTracer wavefront(compiled, settings);
    const auto w = static_cast<std::uint32_t>(compiled.scene().film.width);
    const auto h = static_cast<std::uint32_t>(compiled.scene().film.height);
    for (std::uint32_t s = 0; s < 16; ++s) {
      const FilmSample a = reference.trace_sample(w / 2, h / 2, s, nullptr);
      const FilmSample b = wavefront.trace_sample(w / 2, h / 2, s, nullptr);
      EXPECT_TRUE(is_finite(a.L));
      EXPECT_EQ(a.hits, b.hits) << "sample " << s;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.L[c], b.L[c], 1e-4f * (1.0f + a.L[c])) << "sample " << s;
    }
    ++count;
  }
  EXPECT_GE(count, 3);
}

// The dragon scenes: the full dragon (871,414 triangles, 108 of them
// degenerate and dropped with a warning) once, once smooth-shaded, and four
// times.
TEST(ExampleScenes, BenchScenesLoad) {
  for (const auto& [name, dragons] :
       {std::pair{"dragon.json", 1}, std::pair{"dragon-smooth.json", 1}, std::pair{"dragons-3m.json", 4}}) {
    SCOPED_TRACE(name);
    const Scene scene = load_scene(fs::path(PATHLAB_SOURCE_DIR) / "bench" / "scenes" / name);
    std::size_t triangles = 0;
    for (const Shape& shape : scene.shapes) triangles += shape.mesh.triangles.size();
    EXPECT_GT(triangles, dragons * std::size_t{871'000});
    EXPECT_EQ(scene.warnings.size(), static_cast<std::size_t>(dragons));
    EXPECT_EQ(scene.shapes[1].mesh.has_normals(), std::string_view(name) == "dragon-smooth.json");
  }
}

// bench/scenes/mitsuba-cornell-box.json is Mitsuba 3's mi.cornell_box()
// (bench/mitsuba/mitsuba_scene.py; Mitsuba is not needed here). Pinned: the
// conventions of the translation (Mitsuba's max_depth 8 and rr_depth 5 are
// pathlab's 7 and 4; the film; Mitsuba's one-sided diffuse; the lamp a white
// diffuse that emits on its front only, 0.46 x 0.38 at y = 0.99 facing down),
// and that both tracers follow the same paths through it.
TEST(ExampleScenes, MitsubaCornellBox) {
  Scene scene = load_scene(fs::path(PATHLAB_SOURCE_DIR) / "bench" / "scenes" / "mitsuba-cornell-box.json");
  EXPECT_TRUE(scene.warnings.empty());
  EXPECT_EQ(scene.render.max_depth, 7);
  EXPECT_EQ(scene.render.rr_depth, 4);
  EXPECT_EQ(scene.film.width, 512);
  EXPECT_EQ(scene.film.height, 512);
  EXPECT_EQ(scene.film.filter, FilterKind::Box);
  EXPECT_FLOAT_EQ(scene.camera.fov_y_degrees, 39.3077f);
  EXPECT_EQ(scene.camera.position, vec3(0.0f, 0.0f, 3.9f));
  ASSERT_EQ(scene.shapes.size(), 8u);
  const auto white = std::find_if(scene.materials.begin(), scene.materials.end(),
                                  [](const Material& m) { return m.name == "white"; });
  ASSERT_NE(white, scene.materials.end());
  int lamps = 0;
  for (const Material& m : scene.materials) {
    SCOPED_TRACE(m.name);
    EXPECT_TRUE(m.one_sided);
    EXPECT_EQ(m.type, MaterialType::Diffuse);
    if (!m.emits()) continue;
    ++lamps;
    EXPECT_FALSE(m.two_sided_emission);
    EXPECT_EQ(m.albedo, white->albedo);  // the lamp reflects as the white walls
  }
  EXPECT_EQ(lamps, 1);
  const Shape& lamp = scene.shapes[0];
  ASSERT_TRUE(scene.materials[lamp.material].emits());
  float area = 0.0f;
  for (const glm::uvec3& t : lamp.mesh.triangles) {
    const vec3 a = lamp.mesh.positions[t.x], b = lamp.mesh.positions[t.y], c = lamp.mesh.positions[t.z];
    const vec3 n = glm::cross(b - a, c - a);  // counter-clockwise = front
    area += 0.5f * glm::length(n);
    EXPECT_LT(n.y, 0.0f);                     // emits downwards
    for (const vec3& p : {a, b, c}) EXPECT_NEAR(p.y, 0.99f, 1e-6f);
  }
  EXPECT_NEAR(area, 4.0f * 0.23f * 0.19f, 1e-6f);

  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer reference(compiled, settings);
  const WavefrontTracer wavefront(compiled, settings);
  for (std::uint32_t s = 0; s < 16; ++s) {
    const FilmSample a = reference.trace_sample(256, 300, s, nullptr);
    const FilmSample b = wavefront.trace_sample(256, 300, s, nullptr);
    EXPECT_TRUE(is_finite(a.L));
    EXPECT_EQ(a.hits, b.hits) << "sample " << s;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.L[c], b.L[c], 1e-4f * (1.0f + a.L[c])) << "sample " << s;
  }
}

// The built-in default is scenes/cornell-box.json, compiled in.
TEST(ExampleScenes, BuiltinIsTheCornellBoxFile) {
  const Scene a = builtin_cornell_box();
  const Scene b = load_scene(fs::path(PATHLAB_SOURCE_DIR) / "scenes" / "cornell-box.json");
  ASSERT_EQ(a.shapes.size(), b.shapes.size());
  for (std::size_t i = 0; i < a.shapes.size(); ++i) EXPECT_EQ(a.shapes[i].mesh.positions, b.shapes[i].mesh.positions);
}

}  // namespace
}  // namespace pathlab
