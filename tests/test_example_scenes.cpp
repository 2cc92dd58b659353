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

// The built-in default is scenes/cornell-box.json, compiled in.
TEST(ExampleScenes, BuiltinIsTheCornellBoxFile) {
  const Scene a = builtin_cornell_box();
  const Scene b = load_scene(fs::path(PATHLAB_SOURCE_DIR) / "scenes" / "cornell-box.json");
  ASSERT_EQ(a.shapes.size(), b.shapes.size());
  for (std::size_t i = 0; i < a.shapes.size(); ++i) EXPECT_EQ(a.shapes[i].mesh.positions, b.shapes[i].mesh.positions);
}

}  // namespace
}  // namespace pathlab
