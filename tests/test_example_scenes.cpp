// Every scene shipped in scenes/ loads without a warning, compiles, and
// traces a sample to a finite radiance; the benchmark scenes in bench/scenes/
// load. Some read fetched data ("$data/..."), so these run after the
// pathlab_data fixture.
#include "core/compiled_scene.h"
#include "core/scene_loader.h"
#include "reference/reference_tracer.h"

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
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
    const RenderSettings settings = scene.render;
    const CompiledScene compiled(std::move(scene));
    const ReferenceTracer tracer(compiled, settings);
    const auto w = static_cast<std::uint32_t>(compiled.scene().film.width);
    const auto h = static_cast<std::uint32_t>(compiled.scene().film.height);
    for (std::uint32_t s = 0; s < 16; ++s) EXPECT_TRUE(is_finite(tracer.trace_sample(w / 2, h / 2, s, nullptr).L));
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
