// The wavefront tracer follows the reference's paths: same seed, same
// samples, up to floating-point rounding of the sums.
#include "core/compiled_scene.h"
#include "core/film.h"
#include "core/parallel.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "debugtools/path_compare.h"
#include "debugtools/path_recorder.h"
#include "reference/reference_tracer.h"
#include "tests/test_scenes.h"
#include "wavefront/wavefront_tracer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

namespace pathlab {
namespace {

struct SameSeedCase {
  std::string scene;  // "" = the built-in Cornell box, else a file in analytic-scenes/
  Strategy strategy;
};

Scene load_case(const SameSeedCase& c) {
  Scene s = c.scene.empty() ? builtin_cornell_box()
                            : load_scene(std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes" / c.scene);
  s.film.width = std::min(s.film.width, 32);
  s.film.height = std::min(s.film.height, 24);
  s.render.spp = 4;
  s.render.strategy = c.strategy;
  return s;
}

class SameSeed : public testing::TestWithParam<SameSeedCase> {};

// Every sample of both tracers is compared. A sample counts as equal if its
// radiance agrees within 1e-4 relative (plus 1e-6 absolute for values near 0)
// and it reached as many surfaces and cast as many rays. At least 99.9 % must
// be; each one that is not must be explained by rounding: replayed with both
// tracers, its paths agree event by event (positions and directions within
// 1e-3) up to the vertex where they part, i.e. the same path until a float
// difference flipped a decision, not a different estimator.
TEST_P(SameSeed, WavefrontFollowsTheReferencesPaths) {
  Scene scene = load_case(GetParam());
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer reference(compiled, settings);
  const WavefrontTracer wavefront(compiled, settings, 997);  // several waves, odd size
  const std::size_t pixels = static_cast<std::size_t>(compiled.scene().film.width) * compiled.scene().film.height;
  const auto count = static_cast<std::uint32_t>(settings.spp);
  std::vector<FilmSample> a(pixels * count), b(pixels * count);
  reference.render_batch(0, count, a);
  wavefront.render_batch(0, count, b);
  std::size_t equal = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].film, b[i].film);
    bool same = true;
    for (int c = 0; c < 3; ++c)
      same = same && std::abs(a[i].L[c] - b[i].L[c]) <= 1e-4f * std::max(std::abs(a[i].L[c]), std::abs(b[i].L[c])) + 1e-6f;
    same = same && a[i].hits == b[i].hits && a[i].rays == b[i].rays;
    if (same) {
      ++equal;
      continue;
    }
    const auto x = static_cast<std::uint32_t>((i / count) % compiled.scene().film.width);
    const auto y = static_cast<std::uint32_t>((i / count) / compiled.scene().film.width);
    PathRecorder ra, rb;
    reference.trace_sample(x, y, static_cast<std::uint32_t>(i % count), &ra);
    wavefront.trace_sample(x, y, static_cast<std::uint32_t>(i % count), &rb);
    const PathDivergence d = first_divergence(ra.events(), rb.events(), 1e-3f);
    EXPECT_TRUE(d.rounding) << "pixel " << x << "," << y << " sample " << i % count << ": " << d.reason;
  }
  EXPECT_GE(static_cast<double>(equal), 0.999 * static_cast<double>(a.size()))
      << a.size() - equal << " of " << a.size() << " samples differ";
}

std::vector<SameSeedCase> same_seed_cases() {
  std::vector<std::string> scenes{""};
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes"))
    if (e.path().extension() == ".json") scenes.push_back(e.path().filename().string());
  std::sort(scenes.begin(), scenes.end());
  std::vector<SameSeedCase> cases;
  for (const std::string& s : scenes)
    for (Strategy st : test::kAllStrategies) cases.push_back({s, st});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(AllScenes, SameSeed, testing::ValuesIn(same_seed_cases()),
                         [](const testing::TestParamInfo<SameSeedCase>& p) {
                           std::string s = (p.param.scene.empty() ? std::string("cornell") : p.param.scene) + "_" +
                                           strategy_name(p.param.strategy);
                           for (char& ch : s)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return s;
                         });

TEST(Wavefront, SameBitsForOneAndTwoThreadsAndAnyWaveSize) {
  Scene scene = test::small_cornell(20, 6, FilterKind::Bilinear);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  auto render_image = [&](int threads, std::size_t wave) {
    const ThreadLimit limit(threads);
    const WavefrontTracer tracer(compiled, settings, wave);
    Film film(20, 20, FilterKind::Bilinear);
    render(tracer, film);
    return film.image();
  };
  const Image a = render_image(1, WavefrontTracer::kDefaultWaveSize), b = render_image(2, WavefrontTracer::kDefaultWaveSize),
              c = render_image(2, 17);
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(vec3)), 0);
  EXPECT_EQ(std::memcmp(a.pixels.data(), c.pixels.data(), a.pixels.size() * sizeof(vec3)), 0);
}

// times() counts every ray the render counts, by kind, and the time inside
// Embree is part of the waves' time.
TEST(Wavefront, TimesCountEveryQuery) {
  Scene scene = test::small_cornell(16, 4, FilterKind::Box);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const WavefrontTracer tracer(compiled, settings);
  Film film(16, 16, FilterKind::Box);
  const RenderStats stats = render(tracer, film);
  const WavefrontTimes t = tracer.times();
  EXPECT_EQ(t.camera.rays, stats.samples);
  EXPECT_GT(t.bounce.rays, 0u);
  EXPECT_GT(t.shadow.rays, 0u);
  EXPECT_EQ(t.camera.rays + t.bounce.rays + t.shadow.rays, stats.rays);
  EXPECT_GT(t.query_seconds(), 0.0);
  EXPECT_LE(t.query_seconds(), t.waves_seconds);
}

}  // namespace
}  // namespace pathlab
