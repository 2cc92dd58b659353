// Stochastic alpha (core/alpha.h): a surface of coverage a stops a ray with
// probability a, decided inside Embree's traversal by a hash of the ray's
// key and the surface. Counts of camera and shadow rays against their
// binomial laws (fixed seeds; each z-test at a false-alarm rate of 1e-4),
// the same decisions in both tracers and in every ray mode, and the same
// image bits for any thread count, wave size and ray mode.
#include "core/alpha.h"
#include "core/compiled_scene.h"
#include "core/embree_accel.h"
#include "core/film.h"
#include "core/parallel.h"
#include "core/render.h"
#include "core/sampling.h"
#include "core/scene_loader.h"
#include "reference/reference_tracer.h"
#include "tests/stat_util.h"
#include "tests/temp_dir.h"
#include "tests/test_scenes.h"
#include "tests/texture_util.h"
#include "wavefront/wavefront_tracer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace pathlab {
namespace {

// |z| beyond which one binomial count is called wrong: P = 1e-4 under the law.
const double kZ = test::z_critical(1e-4);

// The z-score of `k` successes in `n` trials of probability `p`.
double binomial_z(std::size_t k, std::size_t n, double p) {
  const double nd = static_cast<double>(n);
  return (static_cast<double>(k) - nd * p) / std::sqrt(nd * p * (1.0 - p));
}

// Every sample of a render of `scene` by one tracer, in the order
// render_batch writes them.
std::vector<FilmSample> samples(const Tracer& tracer) {
  const Scene& s = tracer.scene().scene();
  std::vector<FilmSample> out(static_cast<std::size_t>(s.film.width) * s.film.height * s.render.spp);
  tracer.render_batch(0, static_cast<std::uint32_t>(s.render.spp), out);
  return out;
}

// A camera at z = 4 looking down -z through black quads of coverage `alpha`
// (z = 0, -0.25, ...; as shapes, or as instances of one group) at an
// emitter of radiance 1 at z = -2 that fills the view. With a depth cap of 0
// a sample is 1 if its camera ray reached the emitter, else 0.
Scene layers(int count, float alpha, bool instanced, const std::string& alpha_json = "",
             const std::filesystem::path& file = "layers.json") {
  std::string quads, groups;
  for (int k = 0; k < count; ++k) {
    const std::string z = std::to_string(-0.25 * k);
    if (instanced)
      quads += std::string(k ? ", " : "") + "{\"translate\": [0, 0, " + z + "]}";
    else
      quads += ", {\"type\": \"rectangle\", \"material\": \"leaf\", \"transform\": [{\"scale\": 4}, {\"translate\": [0, 0, " +
               z + "]}]}";
  }
  if (instanced) {
    groups = R"(, "groups": {"leaf": [{"type": "rectangle", "material": "leaf", "transform": {"scale": 4}}]},
                 "instances": [{"group": "leaf", "transforms": [)" + quads + "]}]";
    quads.clear();
  }
  return parse_scene(R"({
    "pathlab_scene": 1,
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov_y": 30},
    "film": {"resolution": [32, 32]},
    "render": {"spp": 16, "max_depth": 0, "strategy": "bsdf", "seed": 7},
    "materials": {"leaf": {"type": "diffuse", "albedo": 0, "alpha": )" +
                         (alpha_json.empty() ? std::to_string(alpha) : alpha_json) + R"(},
                  "lamp": {"type": "emissive", "radiance": 1}},
    "shapes": [{"type": "rectangle", "material": "lamp", "transform": [{"scale": 10}, {"translate": [0, 0, -2]}]})" +
                         quads + "]" + groups + "}",
                     file);
}

// The camera rays that pass every layer, counted in both tracers, which
// must agree sample by sample (the same keys, the same decisions).
std::size_t passed(Scene scene, std::size_t* n) {
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  EXPECT_TRUE(compiled.has_alpha());
  const std::vector<FilmSample> a = samples(ReferenceTracer(compiled, settings));
  const std::vector<FilmSample> b = samples(WavefrontTracer(compiled, settings, 997));
  std::size_t k = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].L, b[i].L) << "sample " << i;
    k += a[i].L.x > 0.5f;
  }
  *n = a.size();
  return k;
}

TEST(Alpha, HalfOfTheCameraRaysPassAHalfCoveredQuad) {
  std::size_t n = 0;
  const std::size_t k = passed(layers(1, 0.5f, false), &n);
  EXPECT_LT(std::abs(binomial_z(k, n, 0.5)), kZ) << k << " of " << n;
}

// Two surfaces along one ray are decided independently: 1/4 pass two
// quads, whether they are two shapes or two instances of one (whose
// triangles have the same IDs, so the instance must enter the decision).
TEST(Alpha, AQuarterPassTwoStackedHalfCoveredQuads) {
  for (bool instanced : {false, true}) {
    SCOPED_TRACE(instanced ? "two instances of one quad" : "two quads");
    std::size_t n = 0;
    const std::size_t k = passed(layers(2, 0.5f, instanced), &n);
    EXPECT_LT(std::abs(binomial_z(k, n, 0.25)), kZ) << k << " of " << n;
  }
}

// Coverage 0 never stops a ray, 1 always does (and registers no filter).
TEST(Alpha, CoverageZeroAndOne) {
  std::size_t n = 0;
  EXPECT_EQ(passed(layers(2, 0.0f, false), &n), n);
  Scene opaque = layers(1, 1.0f, false);
  const RenderSettings settings = opaque.render;
  const CompiledScene compiled(std::move(opaque));
  EXPECT_FALSE(compiled.has_alpha());
  for (const FilmSample& s : samples(ReferenceTracer(compiled, settings))) EXPECT_EQ(s.L.x, 0.0f);
}

class AlphaTexture : public test::TempDirTest {};

// A cut-out: a 2x1 alpha texture, opaque on the left texel and clear on the
// right, on the quad that fills the view (u = (x + 4) / 8). Read at the
// nearest texel, it stops every camera ray of the image's left half and
// none of the right half, in both tracers.
TEST_F(AlphaTexture, CutsOutTheClearTexels) {
  test::write_image(dir_ / "cut.exr", 2, 1, 1, {1.0f, 0.0f});
  const std::filesystem::path file = dir_ / "cut.json";
  Scene scene = layers(1, 1.0f, false, R"({"texture": "cut.exr"})", file);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  ASSERT_TRUE(compiled.has_alpha());
  const std::vector<FilmSample> a = samples(ReferenceTracer(compiled, settings));
  const std::vector<FilmSample> b = samples(WavefrontTracer(compiled, settings, 997));
  const auto count = static_cast<std::size_t>(settings.spp);
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::size_t x = (i / count) % 32;
    ASSERT_EQ(a[i].L.x, x < 16 ? 0.0f : 1.0f) << "sample " << i << ", pixel column " << x;
    ASSERT_EQ(b[i].L, a[i].L) << "sample " << i;
  }
}

// A mask (glTF's alphaMode MASK: Material::alpha_cutoff): coverage at or
// above the cutoff is opaque, below it clear. Texels 0.7 and 0.3 with a
// cutoff of 0.5: the left half stops every ray and the right half none,
// where stochastic coverage would let 30 % and 70 % through.
TEST_F(AlphaTexture, ACutoffMakesTheCoverageAMask) {
  test::write_image(dir_ / "mask.exr", 2, 1, 1, {0.7f, 0.3f});
  Scene scene = layers(1, 1.0f, false, R"({"texture": "mask.exr"})", dir_ / "mask.json");
  for (Material& m : scene.materials)
    if (m.alpha_texture) m.alpha_cutoff = 0.5f;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const std::vector<FilmSample> a = samples(ReferenceTracer(compiled, settings));
  const auto count = static_cast<std::size_t>(settings.spp);
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::size_t x = (i / count) % 32;
    ASSERT_EQ(a[i].L.x, x < 16 ? 0.0f : 1.0f) << "sample " << i << ", pixel column " << x;
  }
}

// A texture of 0.25 everywhere (one channel, linear by default: an sRGB
// decode would make it 0.05): 3/4 of the camera rays pass.
TEST_F(AlphaTexture, GreyTextureIsCoverageReadLinear) {
  test::write_image(dir_ / "grey.png", 2, 2, 1, {0.25f, 0.25f, 0.25f, 0.25f}, OIIO::TypeDesc::UINT8);
  const float texel = std::round(0.25f * 255.0f) / 255.0f;  // what the PNG holds
  std::size_t n = 0;
  const std::size_t k = passed(layers(1, 1.0f, false, R"({"texture": "grey.png"})", dir_ / "grey.json"), &n);
  EXPECT_LT(std::abs(binomial_z(k, n, 1.0 - texel)), kZ) << k << " of " << n;
}

// Shadow rays honour alpha. A directional light of irradiance E, travelling
// along (0.6, -0.8, 0), over a ground of albedo 0.5, under a black quad of
// coverage 0.5 at height 1 that the camera (below it, looking down into its
// shadow) never sees: with a depth cap of 1 a sample is rho/pi E cos V,
// cos = 0.8, and E = pi / 0.4 makes it V, the shadow ray's visibility. The
// ground's irradiance under the quad is E (1 - alpha): half the light.
TEST(Alpha, ShadowRaysPassAHalfCoveredOccluderHalfTheTime) {
  Scene scene = parse_scene(R"({
    "pathlab_scene": 1,
    "camera": {"position": [0.6, 0.5, 0], "look_at": [0.6, 0, 0], "up": [0, 0, -1], "fov_y": 60},
    "film": {"resolution": [32, 32]},
    "render": {"spp": 16, "max_depth": 1, "strategy": "light", "seed": 3},
    "materials": {"ground": {"type": "diffuse", "albedo": 0.5},
                  "leaf": {"type": "diffuse", "albedo": 0, "alpha": 0.5}},
    "shapes": [
      {"type": "rectangle", "material": "ground", "transform": [{"scale": 2}, {"rotate": {"axis": [1, 0, 0], "angle": -90}}]},
      {"type": "rectangle", "material": "leaf",
       "transform": [{"scale": 0.5}, {"rotate": {"axis": [1, 0, 0], "angle": 90}}, {"translate": [0, 1, 0]}]}],
    "lights": [{"type": "directional", "direction": [0.6, -0.8, 0], "irradiance": 7.853981634}]
  })", "shadow.json");
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const std::vector<FilmSample> a = samples(ReferenceTracer(compiled, settings));
  const std::vector<FilmSample> b = samples(WavefrontTracer(compiled, settings, 997));
  std::size_t visible = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_GE(a[i].hits, 1u) << "sample " << i << ": the camera ray must reach the ground";
    EXPECT_EQ(a[i].L.x > 0.5f, b[i].L.x > 0.5f) << "sample " << i;
    EXPECT_TRUE(a[i].L.x == 0.0f || std::abs(a[i].L.x - 1.0f) < 1e-5f) << a[i].L.x;
    visible += a[i].L.x > 0.5f;
  }
  EXPECT_LT(std::abs(binomial_z(visible, a.size(), 0.5)), kZ) << visible << " of " << a.size();
}

// n rays from inside the Cornell box over the sphere of directions, each
// with its own key; every third stops short.
std::vector<Ray> keyed_rays(std::size_t n) {
  std::vector<Ray> rays(n);
  for (std::size_t i = 0; i < n; ++i) {
    const vec2 u((static_cast<float>(i) + 0.5f) / static_cast<float>(n), std::fmod(0.618034f * i, 1.0f));
    rays[i] = Ray{vec3(0.1f, -0.2f, 0.3f), square_to_uniform_sphere(u), i % 3 == 0 ? 0.5f : kInfinity,
                  static_cast<std::uint32_t>(i * 2654435761u)};
  }
  return rays;
}

// Embree may call a filter several times per triangle and in any order; the
// decision is a pure function, so every mode and layout finds the one-ray
// answer, on a world-space box and inside instances. Some rays must pass
// through a surface, or the test proves nothing.
TEST(Alpha, EveryRayModeAndLayoutMakesTheSameDecisions) {
  const Scene scene = test::cornell_with_alpha();
  const EmbreeAccel accel(scene.shapes, scene.groups, scene.instances, BvhOptions{}, scene.materials);
  const EmbreeAccel opaque(scene.shapes, scene.groups, scene.instances);
  const std::size_t n = 600;
  const std::vector<Ray> rays = keyed_rays(n);
  std::vector<float> ox(n), oy(n), oz(n), dx(n), dy(n), dz(n), tmax(n);
  std::vector<std::uint32_t> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    ox[i] = rays[i].origin.x, oy[i] = rays[i].origin.y, oz[i] = rays[i].origin.z;
    dx[i] = rays[i].dir.x, dy[i] = rays[i].dir.y, dz[i] = rays[i].dir.z, tmax[i] = rays[i].tmax, key[i] = rays[i].alpha_key;
  }
  const RayArrays arrays{ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), tmax.data(), key.data()};
  std::size_t passed_through = 0;
  for (std::size_t i = 0; i < n; ++i) {
    RayHit a, b;
    const bool ha = accel.intersect(rays[i], &a), hb = opaque.intersect(rays[i], &b);
    passed_through += ha != hb || (ha && (a.shape != b.shape || a.instance != b.instance));
  }
  EXPECT_GT(passed_through, n / 20);
  for (RayBatchMode mode : kAllRayBatchModes) {
    for (bool coherent : {false, true}) {
      SCOPED_TRACE(testing::Message() << ray_batch_mode_name(mode) << (coherent ? ", coherent" : ""));
      std::vector<RayHit> hits(n);
      std::vector<std::uint8_t> found(n), blocked(n), found_a(n), blocked_a(n);
      std::vector<float> t(n), u(n), v(n);
      std::vector<std::uint32_t> shape(n), prim(n), instance(n);
      accel.intersect_batch(rays, hits, found, mode, coherent);
      accel.occluded_batch(rays, blocked, mode, coherent);
      accel.intersect_arrays(arrays, n, HitArrays{t.data(), u.data(), v.data(), shape.data(), prim.data(), found_a.data(), instance.data()},
                             mode, coherent);
      accel.occluded_arrays(arrays, n, blocked_a.data(), mode, coherent);
      for (std::size_t i = 0; i < n; ++i) {
        RayHit one;
        const bool hit = accel.intersect(rays[i], &one);
        const bool occluded = accel.occluded(rays[i]);
        ASSERT_EQ(found[i], hit) << "ray " << i;
        ASSERT_EQ(found_a[i], hit) << "ray " << i;
        ASSERT_EQ(blocked[i], occluded) << "ray " << i;
        ASSERT_EQ(blocked_a[i], occluded) << "ray " << i;
        if (!hit) continue;
        EXPECT_EQ(hits[i].shape, one.shape);
        EXPECT_EQ(hits[i].prim, one.prim);
        EXPECT_EQ(hits[i].instance, one.instance);
        EXPECT_EQ(shape[i], one.shape);
        EXPECT_EQ(prim[i], one.prim);
        EXPECT_EQ(instance[i], one.instance);
        EXPECT_FLOAT_EQ(hits[i].t, one.t);
      }
    }
  }
}

// The alpha Cornell box (test_scenes.h): for every way the wavefront's rays
// reach Embree, the image is the same, bit for bit, for 1 and 2 threads and
// two wave sizes; and in every mode the samples make the reference's
// decisions: they reach as many surfaces, cast as many rays and carry the
// same radiance (within 1e-4 relative) - all but the rare sample where a
// floating-point difference flips a decision, as in SameSeed. (Across modes
// the bits differ, with or without alpha: Embree's single-ray and packet
// kernels round hit distances and barycentrics differently.)
TEST(Alpha, SameBitsForAnyThreadCountAndWaveSizeAndSamePathsInEveryRayMode) {
  Scene scene = test::cornell_with_alpha();
  scene.film.width = scene.film.height = 16;
  scene.render.spp = 4;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const std::vector<FilmSample> reference = samples(ReferenceTracer(compiled, settings));
  using M = RayBatchMode;
  const WavefrontRayModes all_modes[] = {{M::Single, M::Single, M::Single},
                                         {M::Packet16, M::Packet16, M::Packet16},
                                         {M::Stream, M::Stream, M::Stream},
                                         {M::Packet16, M::Single, M::Stream}};
  for (const WavefrontRayModes& modes : all_modes) {
    SCOPED_TRACE(testing::Message() << ray_batch_mode_name(modes.camera) << "/" << ray_batch_mode_name(modes.bounce)
                                    << "/" << ray_batch_mode_name(modes.shadow));
    const auto image = [&](int threads, std::size_t wave) {
      const ThreadLimit limit(threads);
      const WavefrontTracer tracer(compiled, settings, wave, modes);
      Film film(16, 16, FilterKind::Box);
      render(tracer, film);
      return film.image();
    };
    const Image base = image(1, WavefrontTracer::kDefaultWaveSize);
    for (const auto& [threads, wave] : {std::pair{2, WavefrontTracer::kDefaultWaveSize}, std::pair{1, std::size_t{17}},
                                        std::pair{2, std::size_t{17}}}) {
      const Image img = image(threads, wave);
      EXPECT_EQ(std::memcmp(img.pixels.data(), base.pixels.data(), base.pixels.size() * sizeof(vec3)), 0)
          << threads << " threads, waves of " << wave;
    }
    const std::vector<FilmSample> b = samples(WavefrontTracer(compiled, settings, 997, modes));
    std::size_t same = 0;
    for (std::size_t i = 0; i < b.size(); ++i) {
      const FilmSample& a = reference[i];
      bool equal = a.hits == b[i].hits && a.rays == b[i].rays;
      for (int c = 0; c < 3; ++c)
        equal = equal && std::abs(a.L[c] - b[i].L[c]) <= 1e-4f * std::max(std::abs(a.L[c]), std::abs(b[i].L[c])) + 1e-6f;
      same += equal;
    }
    EXPECT_GE(static_cast<double>(same), 0.999 * static_cast<double>(b.size())) << b.size() - same << " samples differ";
  }
}

// The tracers' keys: each vertex's rays have their own, drawn from the
// sample contract, and a scene without alpha draws none.
TEST(Alpha, KeysComeFromTheSampleContract) {
  const SampleStream rng(5, 17, 3);
  EXPECT_EQ(alpha_key(rng, 2), static_cast<std::uint32_t>(rng.bits(2, Dim::Alpha) >> 32));
  EXPECT_NE(alpha_key(rng, 1), alpha_key(rng, 2));
  EXPECT_EQ(rng.get(2, Dim::Alpha), to_unit_float(rng.bits(2, Dim::Alpha)));
  const CompiledScene opaque(builtin_cornell_box());
  EXPECT_EQ(opaque.alpha_key(rng, 2), 0u);
  const CompiledScene leafy(test::cornell_with_alpha());
  EXPECT_EQ(leafy.alpha_key(rng, 2), alpha_key(rng, 2));
}

}  // namespace
}  // namespace pathlab
