// The wavefront tracer follows the reference's paths: same seed, same
// samples, up to floating-point rounding of the sums.
#include "core/compiled_scene.h"
#include "core/environment_map.h"
#include "core/film.h"
#include "core/parallel.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "core/simd/simd.h"
#include "debugtools/bounce_aov.h"
#include "debugtools/compare.h"
#include "debugtools/path_compare.h"
#include "debugtools/path_recorder.h"
#include "reference/reference_tracer.h"
#include "tests/test_scenes.h"
#include "wavefront/vector_stages.h"
#include "wavefront/wavefront_tracer.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <filesystem>

namespace pathlab {
namespace {

struct SameSeedCase {
  // "" = the built-in Cornell box, "smooth" / "instanced" / "delta" / "alpha" / "textured" /
  // "textured-meshes" (test_scenes.h),
  // "envmap" / "bulb" (below), else a file in analytic-scenes/
  std::string scene;
  Strategy strategy;
  LightSampling light_sampling = LightSampling::Area;
  LightSamplerKind light_sampler = LightSamplerKind::Power;
};

// An environment image lighting a diffuse sphere on a rough metal ground,
// seen from above: light sampling, BSDF sampling and escapes all weigh the
// map (analytic-scenes/structured-16x8.hdr, turned 30 degrees).
Scene envmap_scene() {
  Scene s = load_scene(std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes" / "envmap-mirror-sphere.json");
  s.analytic.clear();
  s.materials[0].type = MaterialType::Diffuse;
  s.materials[0].albedo = Spectrum(0.7f, 0.6f, 0.5f);
  const Scene metal = parse_scene(R"({"pathlab_scene": 1, "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0]},
    "materials": {"metal": {"type": "disney", "base_color": 0.8, "metallic": 1, "roughness": 0.3}},
    "shapes": [{"type": "rectangle", "material": "metal",
                "transform": [{"scale": 4}, {"rotate": {"axis": [1, 0, 0], "angle": -90}}, {"translate": [0, -1, 0]}]}]})",
                                  "ground.json");
  s.materials.push_back(metal.materials[0]);
  Shape ground = metal.shapes[0];
  ground.material = 1;
  s.shapes.push_back(ground);
  return s;
}

// The Cornell box with a small sphere light in the air, seen from outside
// by every surface (cone sampling under light_sampling solid_angle): its
// shadow rays end just before the sphere, some of them grazing it.
Scene cornell_with_bulb() {
  Scene scene = builtin_cornell_box();
  Shape bulb;
  bulb.description = "bulb";
  bulb.kind = Shape::Kind::Sphere;
  bulb.center = vec3(0.3f, 0.5f, 0.2f);
  bulb.radius = 0.1f;
  for (std::uint32_t m = 0; m < scene.materials.size(); ++m)
    if (scene.materials[m].emits()) bulb.material = m;
  scene.shapes.push_back(bulb);
  return scene;
}

// m, named `name`, appended to the scene's materials: its index.
std::uint32_t add_material(Scene& s, Material m, const char* name) {
  m.name = name;
  s.materials.push_back(std::move(m));
  return static_cast<std::uint32_t>(s.materials.size() - 1);
}

// The Cornell box with every kind of material: the short box gold (Disney, metallic), the tall one glass,
// the back wall a clear-coated velvet (Disney sheen and clearcoat) and the
// red wall a mirror.
Scene cornell_with_materials() {
  Scene s = builtin_cornell_box();
  const auto add = [&s](Material m, const char* name) { return add_material(s, std::move(m), name); };
  DisneyParams gold;
  gold.base_color = Spectrum(1.0f, 0.77f, 0.34f);
  gold.metallic = 1.0f;
  gold.roughness = 0.25f;
  DisneyParams velvet;
  velvet.base_color = Spectrum(0.25f, 0.1f, 0.45f);
  velvet.roughness = 0.9f;
  velvet.sheen = 1.0f;
  velvet.clearcoat = 1.0f;
  velvet.clearcoat_gloss = 0.9f;
  Material mirror = diffuse_material(Spectrum(0.9f, 0.85f, 0.8f));
  mirror.type = MaterialType::Mirror;
  s.shapes.at(2).material = add(disney_material(velvet), "velvet");
  s.shapes.at(3).material = add(std::move(mirror), "mirror");
  s.shapes.at(5).material = add(disney_material(gold), "gold");
  s.shapes.at(6).material = add(dielectric_material({}), "glass");
  return s;
}

// cornell_with_materials() with tangents on the velvet back wall (a shading
// frame of its own: kFramed) beside the gold box (the geometric normal's):
// Disney surfaces of both kinds in one scene.
Scene cornell_with_framed_velvet() {
  Scene s = cornell_with_materials();
  Shape& velvet = s.shapes.at(2);
  velvet.mesh.tangents.assign(velvet.mesh.positions.size(), glm::vec4(0.6f, 0.0f, 0.8f, 1.0f));
  return s;
}

// The Cornell box with a smooth glass sphere (vertex normals, 24 rings) and
// a coarse smooth mirror sphere (8 rings: shading normals far from the
// facets'), shaded in the lanes in the frames resolve() made there, with
// Surfel's rules under a shading normal (the dielectric's wo on one side of
// both normals; reflection on wo's geometric side, transmission across).
Scene cornell_with_smooth_impulses() {
  Scene s = test::cornell_with_smooth_sphere();
  s.shapes.back().material = add_material(s, dielectric_material({}), "glass");
  Shape ball;
  ball.description = "coarse smooth mirror sphere";
  ball.mesh = test::uv_sphere(vec3(0.35f, -0.6f, -0.25f), 0.35f, 8);
  Material mirror = diffuse_material(Spectrum(0.9f, 0.85f, 0.8f));
  mirror.type = MaterialType::Mirror;
  ball.material = add_material(s, std::move(mirror), "mirror");
  s.shapes.push_back(std::move(ball));
  return s;
}

// The Cornell box with a smooth UV sphere (vertex normals: a shading normal
// at almost every hit) of an anisotropic clear-coated Disney plastic, shaded
// in the lanes in the frame resolve() interpolated (kFramed).
Scene cornell_with_smooth_plastic() {
  Scene s = test::cornell_with_smooth_sphere();
  DisneyParams plastic;
  plastic.base_color = Spectrum(0.2f, 0.4f, 0.7f);
  plastic.roughness = 0.35f;
  plastic.anisotropic = 0.6f;
  plastic.sheen = 0.5f;
  plastic.clearcoat = 0.8f;
  s.shapes.back().material = add_material(s, disney_material(plastic), "plastic");
  return s;
}

// cornell_with_materials() whose velvet back wall is an anisotropic
// clear-coated lacquer with energy compensation (its tables gathered in the
// lanes), beside the gold box without.
Scene cornell_with_compensated_lacquer() {
  Scene s = cornell_with_materials();
  DisneyParams lacquer;
  lacquer.base_color = Spectrum(0.6f, 0.1f, 0.05f);
  lacquer.roughness = 0.4f;
  lacquer.anisotropic = 0.8f;
  lacquer.clearcoat = 1.0f;
  lacquer.energy_compensation = true;
  s.shapes.at(2).material = add_material(s, disney_material(lacquer), "lacquer");
  return s;
}

// The Cornell box with tangents on its floor (glTF TANGENT without NORMAL):
// a tangent frame rotates the directions Lambert sampling draws.
Scene cornell_with_tangents() {
  Scene s = builtin_cornell_box();
  for (Shape& shape : s.shapes)
    if (shape.kind == Shape::Kind::Triangles && !s.materials[shape.material].emits()) {
      shape.mesh.tangents.assign(shape.mesh.positions.size(), glm::vec4(1, 0, 0, 1));
      break;
    }
  return s;
}

// cornell_with_instances() with tangents: on the group's smooth UV sphere
// (not perpendicular to its normals, the handedness changing between
// vertices), placed turned, mirrored and sheared; and on the tall box in
// world space, turned inside out (flip_normals: its own normal is the other
// side's). The tangent frames the lanes make (kTangentsAt).
Scene cornell_with_instanced_tangents() {
  Scene s = test::cornell_with_instances();
  Shape& ball = s.shapes[s.groups[0].shapes[0]];
  ball.mesh.tangents.resize(ball.mesh.positions.size());
  for (std::size_t i = 0; i < ball.mesh.positions.size(); ++i) {
    const vec3& p = ball.mesh.positions[i];
    ball.mesh.tangents[i] = glm::vec4(-p.z, 0.3f, p.x + 0.1f, i % 3 == 0 ? -1.0f : 1.0f);
  }
  Shape& box = s.shapes[6];  // the tall box
  box.mesh.tangents.assign(box.mesh.positions.size(), glm::vec4(0.6f, 0.8f, 0.0f, -1.0f));
  box.flip_normals = true;
  return s;
}

// cornell_with_instances() whose group's true sphere glows (an emitter no
// light sample aims at: the loader takes emitters in groups only so), lit
// also by delta lights and the sky: every kind of light at once.
Scene cornell_with_every_light() {
  Scene s = test::cornell_with_instances();
  for (const DeltaLight& d : test::cornell_with_delta_lights().delta_lights) s.delta_lights.push_back(d);
  s.environment = Spectrum(0.2f, 0.3f, 0.4f);
  Material glow = s.materials[s.shapes.back().material];
  glow.name = "glow";
  glow.emission = Spectrum(2.0f, 1.5f, 1.0f);
  glow.sampled_as_light = false;
  s.materials.push_back(glow);
  s.shapes.back().material = static_cast<std::uint32_t>(s.materials.size() - 1);
  return s;
}

// The Cornell box under a sky beside its ceiling light: an environment of
// one radiance and two sun disks through the open front, the small one
// inside the wide one's cone (a direction in both carries both).
Scene cornell_with_sky() {
  Scene s = builtin_cornell_box();
  s.environment = Spectrum(0.2f, 0.3f, 0.4f);
  DeltaLight wide;
  wide.kind = DeltaLight::Kind::Directional;
  wide.direction = glm::normalize(vec3(0.3f, -0.4f, -1.0f));
  wide.intensity = Spectrum(3.0f, 2.5f, 2.0f);
  wide.angular_radius = 0.3f;
  DeltaLight small = wide;
  small.direction = glm::normalize(vec3(0.35f, -0.45f, -1.0f));
  small.intensity = Spectrum(1.0f, 2.0f, 4.0f);
  small.angular_radius = 0.05f;
  s.delta_lights = {wide, small};
  return s;
}

// cornell_with_sky() whose environment is an image (envmap-direct's map, not
// turned): the texels drawn and looked up beside triangle lights and sun disks.
Scene cornell_with_sky_image() {
  Scene s = cornell_with_sky();
  s.environment.reset();
  s.environment_map =
      load_scene(std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes" / "envmap-direct.json").environment_map;
  return s;
}

// cornell_with_sky_image() whose map is patchy and turned: its lower half
// black (rows of density 0: never drawn, escapes there see black at density
// 0), every third texel of the upper half black (cells of width 0 inside the
// rows' cdfs), turned 40 degrees about +y.
Scene cornell_with_patchy_sky() {
  Scene s = cornell_with_sky_image();
  Image texels = s.environment_map->texels();
  for (int y = 0; y < texels.height; ++y)
    for (int x = 0; x < texels.width; ++x)
      if (y >= texels.height / 2 || x % 3 == 0) texels.at(x, y) = Spectrum(0.0f);
  const float c = std::cos(0.7f), sn = std::sin(0.7f);
  const mat3 turn(vec3(c, 0.0f, -sn), vec3(0.0f, 1.0f, 0.0f), vec3(sn, 0.0f, c));
  s.environment_map = std::make_shared<const EnvironmentMap>(std::move(texels), turn, "patchy");
  return s;
}

Scene load_case(const SameSeedCase& c) {
  Scene s = c.scene.empty()          ? builtin_cornell_box()
            : c.scene == "every-light" ? cornell_with_every_light()
            : c.scene == "materials" ? cornell_with_materials()
            : c.scene == "framed-velvet" ? cornell_with_framed_velvet()
            : c.scene == "compensated" ? cornell_with_compensated_lacquer()
            : c.scene == "tangents"  ? cornell_with_tangents()
            : c.scene == "tangents-instanced" ? cornell_with_instanced_tangents()
            : c.scene == "smooth"    ? test::cornell_with_smooth_sphere()
            : c.scene == "instanced" ? test::cornell_with_instances()
            : c.scene == "delta"     ? test::cornell_with_delta_lights()
            : c.scene == "envmap"    ? envmap_scene()
            : c.scene == "alpha"     ? test::cornell_with_alpha()
            : c.scene == "textured"  ? test::cornell_with_textures()
            : c.scene == "textured-impulses" ? test::cornell_with_textures(true)
            : c.scene == "textured-meshes" ? test::cornell_with_textured_meshes()
            : c.scene == "many"      ? test::cornell_with_many_lights()
            : c.scene == "bulb"      ? cornell_with_bulb()
            : c.scene == "sky"       ? cornell_with_sky()
            : c.scene == "smooth-plastic" ? cornell_with_smooth_plastic()
            : c.scene == "smooth-impulses" ? cornell_with_smooth_impulses()
            : c.scene == "sky-image" ? cornell_with_sky_image()
            : c.scene == "patchy-sky" ? cornell_with_patchy_sky()
                                     : load_scene(std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes" / c.scene);
  s.film.width = std::min(s.film.width, 32);
  s.film.height = std::min(s.film.height, 24);
  s.render.spp = 4;
  s.render.strategy = c.strategy;
  s.render.light_sampling = c.light_sampling;
  s.render.light_sampler = c.light_sampler;
  return s;
}

class SameSeed : public testing::TestWithParam<SameSeedCase> {};

// Every sample of both tracers is compared, by the rule `pathlab compare`
// applies (debugtools/compare.h): a sample counts as equal if its radiance
// agrees within 1e-4 relative (plus 1e-6 absolute for values near 0) and it
// reached as many surfaces and cast as many rays. At least 99.9 % must be;
// each one that is not must be explained by rounding: replayed with both
// tracers, its paths agree event by event (positions and directions within
// 1e-3) up to the vertex where they part, i.e. the same path until a float
// difference flipped a decision, not a different estimator.
//
// The per-bounce layers (debugtools/bounce_aov.h) of every sample that
// agrees are the same bits in both tracers: each event's contribution is
// the same product of the same numbers in both.
TEST_P(SameSeed, WavefrontFollowsTheReferencesPaths) {
  Scene scene = load_case(GetParam());
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer reference(compiled, settings);
  const WavefrontTracer wavefront(compiled, settings, 997);  // several waves, odd size
  const auto count = static_cast<std::uint32_t>(settings.spp);
  const SampleComparison r = compare_tracers(reference, wavefront, count);
  for (const SampleDisagreement& d : r.replayed)
    EXPECT_TRUE(d.divergence.rounding) << "pixel " << d.x << "," << d.y << " sample " << d.sample << ": "
                                       << d.divergence.reason;
  EXPECT_GE(static_cast<double>(r.equal), kSameSeedShare * static_cast<double>(r.samples))
      << r.differing() << " of " << r.samples << " samples differ";
  EXPECT_TRUE(r.agree());

  std::size_t layers_equal = 0, compared = 0;
  const FilmDesc& film = compiled.scene().film;
  for (std::uint32_t y = 0; y < static_cast<std::uint32_t>(film.height); ++y)
    for (std::uint32_t x = 0; x < static_cast<std::uint32_t>(film.width); ++x)
      for (std::uint32_t j = 0; j < count; ++j) {
        BounceObserver a, b;
        const FilmSample fa = reference.trace_sample(x, y, j, &a), fb = wavefront.trace_sample(x, y, j, &b);
        if (!same_sample(fa, fb)) continue;  // a path that parted (counted above)
        ++compared;
        bool same = true;
        for (int d = 0; d < kBounceLayers; ++d)
          for (int t = 0; t < kTechniques; ++t) {
            const Spectrum& la = a.layers.L[static_cast<std::size_t>(d)][static_cast<std::size_t>(t)];
            const Spectrum& lb = b.layers.L[static_cast<std::size_t>(d)][static_cast<std::size_t>(t)];
            same = same && la == lb;
            EXPECT_EQ(la, lb) << "pixel " << x << "," << y << " sample " << j << " layer " << bounce_layer_name(d)
                              << "." << technique_name(static_cast<Technique>(t));
          }
        layers_equal += same ? 1 : 0;
      }
  EXPECT_EQ(layers_equal, compared);
}

std::vector<SameSeedCase> same_seed_cases() {
  std::vector<std::string> scenes{""};
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes"))
    if (e.path().extension() == ".json") scenes.push_back(e.path().filename().string());
  std::sort(scenes.begin(), scenes.end());
  scenes.push_back("smooth");     // the Cornell box with a smooth-shaded sphere (test_scenes.h)
  scenes.push_back("instanced");  // the Cornell box with a group placed three times (test_scenes.h)
  scenes.push_back("delta");      // the Cornell box with point, spot and directional lights (test_scenes.h)
  scenes.push_back("envmap");     // an environment image over a diffuse sphere and a metal ground (above)
  scenes.push_back("alpha");      // the instanced Cornell box with partial coverage (test_scenes.h)
  scenes.push_back("textured");   // the Cornell box reading textures everywhere (test_scenes.h)
  scenes.push_back("textured-meshes");  // textured meshes without uvs, smooth, on instances (test_scenes.h)
  scenes.push_back("bulb");       // the Cornell box with a sphere light seen from outside (above)
  scenes.push_back("sky");        // the Cornell box under an environment and two sun disks (above)
  scenes.push_back("sky-image");  // the same under an environment image (above)
  std::vector<SameSeedCase> cases;
  for (const std::string& s : scenes)
    for (Strategy st : test::kAllStrategies) cases.push_back({s, st});
  // Solid-angle light sampling (the wavefront's scalar stages, the same
  // LightSampler): triangle lights, a sphere light seen from inside
  // (white-sphere-emissive-room's room) and from outside ("bulb": cone
  // sampling), textured and delta lights.
  for (const std::string& s : {std::string(""), std::string("penumbra-box.json"), std::string("white-sphere-emissive-room.json"),
                               std::string("penumbra-emissive-polygon.json"), std::string("textured"), std::string("delta"),
                               std::string("bulb")})
    for (Strategy st : test::kAllStrategies) cases.push_back({s, st, LightSampling::SolidAngle});
  // The light BVH (scalar stages, the same LightSampler): many small lights
  // of every orientation in the Cornell box, twelve lighting each other
  // (furnace-box), the sky beside an empty tree (envmap), delta lights; and
  // with solid-angle sampling.
  for (const std::string& s : {std::string("many"), std::string("furnace-box.json"), std::string("envmap"),
                               std::string("delta"), std::string("sky"), std::string("sky-image")})
    for (Strategy st : test::kAllStrategies) cases.push_back({s, st, LightSampling::Area, LightSamplerKind::Bvh});
  for (Strategy st : {Strategy::Light, Strategy::Mis})
    cases.push_back({"many", st, LightSampling::SolidAngle, LightSamplerKind::Bvh});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(AllScenes, SameSeed, testing::ValuesIn(same_seed_cases()),
                         [](const testing::TestParamInfo<SameSeedCase>& p) {
                           std::string s = (p.param.scene.empty() ? std::string("cornell") : p.param.scene) + "_" +
                                           strategy_name(p.param.strategy) +
                                           (p.param.light_sampling == LightSampling::SolidAngle ? "_solid_angle" : "") +
                                           (p.param.light_sampler == LightSamplerKind::Bvh ? "_bvh" : "");
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

// Both tracers give the same bits for one thread and two, and the wavefront
// for any wave size, on a scene the vectorised stages leave to the scalar ones
// (or, with `vectorised_stages`, one they take where the processor runs them).
void expect_same_bits_for_one_and_two_threads(Scene scene, bool vectorised_stages = false) {
  const int width = scene.film.width, height = scene.film.height;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  auto render_image = [&](bool wavefront, int threads, std::size_t wave) {
    const ThreadLimit limit(threads);
    Film film(width, height, FilterKind::Box);
    if (wavefront) {
      const WavefrontTracer tracer(compiled, settings, wave);
      EXPECT_EQ(tracer.vectorised(), vectorised_stages && vector_stages::cpu_supported()) << tracer.scalar_reason();
      render(tracer, film);
    } else {
      const ReferenceTracer tracer(compiled, settings);
      render(tracer, film);
    }
    return film.image();
  };
  for (const bool wavefront : {false, true}) {
    const Image a = render_image(wavefront, 1, WavefrontTracer::kDefaultWaveSize),
                b = render_image(wavefront, 2, wavefront ? 17 : WavefrontTracer::kDefaultWaveSize);
    EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(vec3)), 0) << wavefront;
  }
}

// An environment image.
TEST(Wavefront, EnvironmentMapSameBitsForOneAndTwoThreads) {
  Scene scene = envmap_scene();
  scene.film.width = 16;
  scene.film.height = 12;
  scene.render.spp = 4;
  expect_same_bits_for_one_and_two_threads(std::move(scene), true);
}

// Solid-angle light sampling: the wavefront runs its vectorised stages
// (asserted inside; the light samples drawn in their double lanes), and both
// tracers give the same bits for one thread and two, and the wavefront for
// any wave size, on the Cornell box (triangle lights).
TEST(Wavefront, SolidAngleLightSamplingSameBitsForOneAndTwoThreads) {
  Scene scene = test::small_cornell(16, 4, FilterKind::Box);
  scene.render.light_sampling = LightSampling::SolidAngle;
  expect_same_bits_for_one_and_two_threads(std::move(scene), true);
}

// The light BVH: the wavefront runs its vectorised stages (asserted inside)
// and both tracers give the same bits for one thread and two, and the
// wavefront for any wave size, on the Cornell box with many lights.
TEST(Wavefront, LightBvhSameBitsForOneAndTwoThreads) {
  Scene scene = test::cornell_with_many_lights();
  scene.film.width = scene.film.height = 16;
  scene.render.spp = 4;
  scene.render.light_sampler = LightSamplerKind::Bvh;
  expect_same_bits_for_one_and_two_threads(std::move(scene), true);
}

// The wavefront's image is the same bits for 1 and 2 threads and wave sizes
// 17, 97 and 4096 (short stream batches, odd packets, full ones), on scenes
// with true spheres: a sphere light seen from outside (its shadow rays end on
// the sphere, some grazing it) under area and cone sampling, and a diffuse
// sphere as ordinary geometry (the vectorised stages where the processor has
// them, and the scalar ones). Each image is compared with the first, and the
// count of differing pixels printed.
// `vectorised_stages`: the scene is one the vectorised stages take (asserted
// where the processor has AVX-512).
void expect_same_bits_for_any_wave_size(const Scene& scene_in, WavefrontStages stages, bool vectorised_stages = false) {
  Scene scene = scene_in;
  const int width = scene.film.width, height = scene.film.height;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  auto render_image = [&](int threads, std::size_t wave) {
    const ThreadLimit limit(threads);
    Film film(width, height, FilterKind::Box);
    const WavefrontTracer tracer(compiled, settings, wave, {}, stages);
    if (stages == WavefrontStages::Auto && vectorised_stages) {
      EXPECT_EQ(tracer.vectorised(), vector_stages::cpu_supported()) << tracer.scalar_reason();
    }
    render(tracer, film);
    return film.image();
  };
  const Image first = render_image(1, WavefrontTracer::kDefaultWaveSize);
  for (const std::size_t wave : {std::size_t{17}, std::size_t{97}, WavefrontTracer::kDefaultWaveSize})
    for (const int threads : {1, 2}) {
      if (wave == WavefrontTracer::kDefaultWaveSize && threads == 1) continue;
      const Image other = render_image(threads, wave);
      std::size_t differing = 0;
      for (std::size_t i = 0; i < first.pixels.size(); ++i)
        differing += std::memcmp(&first.pixels[i], &other.pixels[i], sizeof(vec3)) != 0 ? 1 : 0;
      EXPECT_EQ(differing, 0u) << (stages == WavefrontStages::Scalar ? "scalar stages" : "stages as the scene allows")
                               << ", wave size " << wave << ", " << threads << " thread(s): " << differing << " of "
                               << first.pixels.size() << " pixels differ from 1 thread at wave size 4096";
    }
}

Scene small_bulb(LightSampling sampling) {
  Scene scene = cornell_with_bulb();
  scene.film.width = scene.film.height = 32;
  scene.render.spp = 4;
  scene.render.light_sampling = sampling;
  return scene;
}

TEST(Wavefront, SphereLightSameBitsForAnyWaveSizeAndThreads) {
  expect_same_bits_for_any_wave_size(small_bulb(LightSampling::Area), WavefrontStages::Auto);
}

TEST(Wavefront, SolidAngleSphereLightSameBitsForAnyWaveSizeAndThreads) {
  expect_same_bits_for_any_wave_size(small_bulb(LightSampling::SolidAngle), WavefrontStages::Auto);
}

// The Cornell box with a diffuse true sphere on its floor (not a light).
Scene cornell_with_ball() {
  Scene scene = builtin_cornell_box();
  Shape ball;
  ball.description = "ball";
  ball.kind = Shape::Kind::Sphere;
  ball.center = vec3(-0.35f, -0.6f, 0.15f);
  ball.radius = 0.4f;
  ball.material = scene.shapes.front().material;
  scene.shapes.push_back(ball);
  scene.film.width = scene.film.height = 32;
  scene.render.spp = 8;
  return scene;
}

TEST(Wavefront, DiffuseSphereSameBitsForAnyWaveSizeAndThreads) {
  expect_same_bits_for_any_wave_size(cornell_with_ball(), WavefrontStages::Auto, true);
  expect_same_bits_for_any_wave_size(cornell_with_ball(), WavefrontStages::Scalar);
}

// And the reference tracer for one thread and two on the bulb.
TEST(Wavefront, SolidAngleSphereLightSameBitsForOneAndTwoThreads) {
  expect_same_bits_for_one_and_two_threads(small_bulb(LightSampling::SolidAngle), true);
}

// A textured scene (texture lookups, cones, normal maps, textured emission).
TEST(Wavefront, TexturedSceneSameBitsForOneAndTwoThreads) {
  Scene scene = test::cornell_with_textures();
  scene.film.width = scene.film.height = 16;
  expect_same_bits_for_one_and_two_threads(std::move(scene), true);
}

// The render driver hands tracers a SampleBuffer nobody has written, so a
// tracer must write every field of every sample: the same batch traced over
// zeros and over a byte pattern must come out the same, bit for bit.
TEST(Tracers, WriteEveryFieldOfEverySample) {
  static_assert(sizeof(FilmSample) == 2 * sizeof(float) + 3 * sizeof(float) + 2 * sizeof(std::uint32_t),
                "no padding, so memcmp compares fields only");
  Scene scene = test::small_cornell(12, 3, FilterKind::Box);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer reference(compiled, settings);
  const WavefrontTracer vector(compiled, settings, 61), scalar(compiled, settings, 61, {}, WavefrontStages::Scalar);
  for (const Tracer* tracer : std::initializer_list<const Tracer*>{&reference, &vector, &scalar}) {
    std::vector<FilmSample> zeros(12 * 12 * 3), pattern(zeros.size());
    std::memset(static_cast<void*>(zeros.data()), 0, zeros.size() * sizeof(FilmSample));
    std::memset(static_cast<void*>(pattern.data()), 0xa5, pattern.size() * sizeof(FilmSample));
    tracer->render_batch(0, 3, zeros);
    tracer->render_batch(0, 3, pattern);
    EXPECT_EQ(std::memcmp(zeros.data(), pattern.data(), zeros.size() * sizeof(FilmSample)), 0) << tracer->name();
  }
}

// Both tracers report the rays they cast (LightEvent::ray,
// ScatterEvent::next; the raw-rate benchmark casts exactly these): each
// leaves the surface it starts on, the shadow ray ends at the light sample's
// point and the continuation goes along the sampled direction - and the two
// tracers' rays agree.
TEST(Wavefront, EventsCarryTheRaysAsCast) {
  Scene scene = test::small_cornell(12, 1, FilterKind::Box);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer reference(compiled, settings);
  const WavefrontTracer wavefront(compiled, settings);
  std::size_t shadow_rays = 0, continuations = 0;
  for (std::uint32_t y = 0; y < 12; ++y)
    for (std::uint32_t x = 0; x < 12; ++x) {
      PathRecorder ra, rb;
      reference.trace_sample(x, y, 0, &ra);
      wavefront.trace_sample(x, y, 0, &rb);
      const PathDivergence d = first_divergence(ra.events(), rb.events(), 1e-4f);
      EXPECT_TRUE(d.identical || d.rounding) << x << "," << y << ": " << d.reason;
      vec3 p(0.0f);
      for (const PathEvent& e : ra.events()) {
        if (const auto* h = std::get_if<HitEvent>(&e)) p = h->p;
        if (const auto* l = std::get_if<LightEvent>(&e); l != nullptr && l->rejected == LightRejection::None) {
          ++shadow_rays;  // a rejected light sample casts no shadow ray
          EXPECT_LT(glm::length(l->ray.origin - p), 1e-3f);
          EXPECT_GT(glm::dot(l->ray.dir, l->wi), 0.9999f);
          ASSERT_TRUE(std::isfinite(l->ray.tmax));
          EXPECT_LT(glm::length(l->ray.origin + l->ray.tmax * l->ray.dir - l->point), 1e-3f);
        }
        if (const auto* sc = std::get_if<ScatterEvent>(&e); sc && !is_black(sc->throughput)) {
          ++continuations;
          EXPECT_LT(glm::length(sc->next.origin - p), 1e-3f);
          EXPECT_EQ(sc->next.dir, sc->wi);
          EXPECT_EQ(sc->next.tmax, kInfinity);
        }
      }
    }
  EXPECT_GT(shadow_rays, 100u);
  EXPECT_GT(continuations, 100u);
}

// The vectorised stages (wavefront/vector_stages.h) give every sample the
// bits the scalar stages give it, on every scene and strategy they take:
// several lights (the pick's binary search), a two-sided emitting box, a
// min_pdf cut-off, roulette from the first bounce, waves whose size is not
// a multiple of 16 lanes, and every way rays reach Embree (single rays,
// packets, streams: the vectorised stages hand Embree arrays, the scalar
// ones records).
struct VectorCase {
  std::string scene;  // as SameSeedCase
  Strategy strategy;
  float min_pdf = 0.0f;
  int rr_depth = -1;  // -1: the scene's
  bool thin_lens = false;
  bool tilted = false;  // the whole scene turned off the axes, so that no normal is axis-aligned
  bool crowded = false;  // more than 16 shapes and lights (tables gathered, not permuted)
  bool one_sided = false;  // every diffuse material one-sided, and every other mesh turned inside out
                           // (its triangles' winding reversed), so that paths meet backs too
  bool zsobol = false;     // the zsobol sampler (Sobol' points, core/simd/sobol-inl.h in the lanes)
  int spp = 0;             // 0: the scene's (an odd log2 of it gives zsobol's index a lone lowest bit)
  bool bvh = false;        // light_sampler bvh (the tree walked in double lanes, core/simd/light_bvh-inl.h)
  bool general_shading = false;  // every material through the Disney closure (--general-shading)
  bool solid_angle = false;      // light_sampling solid_angle (core/simd/spherical-inl.h in double lanes)
  bool cospow = false;           // bsdf_sampling cospow (Disney's glossy lobes by core/bsdf/cospow-inl.h)
};

// Every diffuse material one-sided (black behind its geometric normal), and
// every other mesh's triangles wound the other way round.
void make_one_sided(Scene& scene) {
  for (Material& m : scene.materials)
    if (m.type == MaterialType::Diffuse) m.one_sided = true;
  for (std::size_t i = 0; i < scene.shapes.size(); i += 2)
    if (scene.shapes[i].kind == Shape::Kind::Triangles && !scene.materials[scene.shapes[i].material].emits())
      for (glm::uvec3& t : scene.shapes[i].mesh.triangles) std::swap(t.y, t.z);
}

// The scene and its camera turned by 37 degrees about (1, 2, 3).
void tilt(Scene& scene) {
  const mat3 r(glm::rotate(mat4(1.0f), glm::radians(37.0f), glm::normalize(vec3(1.0f, 2.0f, 3.0f))));
  for (Shape& shape : scene.shapes) {
    for (vec3& p : shape.mesh.positions) p = r * p;
    shape.center = r * shape.center;
  }
  scene.camera.position = r * scene.camera.position;
  scene.camera.look_at = r * scene.camera.look_at;
  scene.camera.up = r * scene.camera.up;
}

// The same scene as one shape per triangle, each emitting triangle first cut
// into 16: more than 16 shapes and light entries, so that the vectorised stages
// gather from their tables instead of permuting registers.
void crowd(Scene& scene) {
  std::vector<Shape> shapes;
  for (const Shape& shape : scene.shapes) {
    if (shape.kind != Shape::Kind::Triangles) {
      shapes.push_back(shape);
      continue;
    }
    const bool emits = scene.materials[shape.material].emits();
    for (const glm::uvec3& t : shape.mesh.triangles) {
      Shape one = shape;
      one.mesh.positions = {shape.mesh.positions[t.x], shape.mesh.positions[t.y], shape.mesh.positions[t.z]};
      one.mesh.triangles = {glm::uvec3(0, 1, 2)};
      for (int split = 0; emits && split < 2; ++split) {  // each triangle into 4, twice
        TriangleMesh finer;
        for (const glm::uvec3& f : one.mesh.triangles) {
          const vec3 a = one.mesh.positions[f.x], b = one.mesh.positions[f.y], c = one.mesh.positions[f.z];
          const vec3 ab = 0.5f * (a + b), bc = 0.5f * (b + c), ca = 0.5f * (c + a);
          for (const std::array<vec3, 3>& g : {std::array<vec3, 3>{a, ab, ca}, std::array<vec3, 3>{ab, b, bc},
                                                std::array<vec3, 3>{ca, bc, c}, std::array<vec3, 3>{ab, bc, ca}}) {
            const auto i = static_cast<std::uint32_t>(finer.positions.size());
            finer.positions.insert(finer.positions.end(), g.begin(), g.end());
            finer.triangles.emplace_back(i, i + 1, i + 2);
          }
        }
        one.mesh = std::move(finer);
      }
      for (const glm::uvec3& f : one.mesh.triangles) {
        Shape piece = one;
        piece.mesh.positions = {one.mesh.positions[f.x], one.mesh.positions[f.y], one.mesh.positions[f.z]};
        piece.mesh.triangles = {glm::uvec3(0, 1, 2)};
        shapes.push_back(std::move(piece));
      }
    }
  }
  scene.shapes = std::move(shapes);
}

// Dispatch runs `t` while it lives.
struct SimdChoice {
  explicit SimdChoice(SimdTarget t) { select_simd_target(t); }
  ~SimdChoice() { select_simd_target(SimdTarget::Auto); }
  SimdChoice(const SimdChoice&) = delete;
  SimdChoice& operator=(const SimdChoice&) = delete;
};

class VectorStages : public testing::TestWithParam<VectorCase> {};

TEST_P(VectorStages, GiveTheScalarStagesBits) {
  const VectorCase& c = GetParam();
  Scene scene = load_case({c.scene, c.strategy});
  scene.render.min_pdf = c.min_pdf;
  if (c.rr_depth >= 0) scene.render.rr_depth = c.rr_depth;
  if (c.tilted) tilt(scene);
  if (c.crowded) crowd(scene);
  if (c.one_sided) make_one_sided(scene);
  if (c.zsobol) scene.render.sampler = SamplerKind::ZSobol;
  if (c.spp > 0) scene.render.spp = c.spp;
  if (c.bvh) scene.render.light_sampler = LightSamplerKind::Bvh;
  scene.render.force_general_shading = c.general_shading;
  if (c.solid_angle) scene.render.light_sampling = LightSampling::SolidAngle;
  if (c.cospow) scene.render.bsdf_sampling = BsdfSampling::Cospow;
  if (c.thin_lens) {
    scene.camera.aperture_radius = 0.1f;
    scene.camera.focus_distance = 3.0f;
  }
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  if (c.crowded) {
    ASSERT_GT(compiled.scene().shapes.size(), 16u);
    ASSERT_GT(compiled.lights().entries().size(), 16u);
  }
  const std::size_t pixels = static_cast<std::size_t>(compiled.scene().film.width) * compiled.scene().film.height;
  const auto count = static_cast<std::uint32_t>(settings.spp);
  // The default ray modes at two wave sizes, and each mode for every kind of ray.
  struct Run {
    std::size_t wave;
    WavefrontRayModes modes;
  };
  std::vector<Run> runs{{997, {}}, {4096, {}}};
  for (RayBatchMode m : kAllRayBatchModes) runs.push_back({997, {m, m, m}});
  // The scalar stages' samples, once per run; then every vector target's.
  std::vector<std::vector<FilmSample>> expected;
  for (const auto& [wave, modes] : runs) {
    const WavefrontTracer scalar(compiled, settings, wave, modes, WavefrontStages::Scalar);
    ASSERT_FALSE(scalar.vectorised());
    expected.emplace_back(pixels * count);
    scalar.render_batch(0, count, expected.back());
  }
  std::vector<SimdTarget> targets = supported_simd_targets();
  std::erase(targets, SimdTarget::Scalar);
  ASSERT_FALSE(targets.empty()) << "no vector SIMD target (every x86-64 CI machine has AVX2 and SSE4)";
  for (SimdTarget target : targets) {
    const SimdChoice choice(target);
    // Small waves too: a wave that is not a whole number of blocks, and one smaller than a block.
    std::vector<Run> target_runs = runs;
    if (target == targets.front()) target_runs.push_back({3, {}});
    for (std::size_t r = 0; r < target_runs.size(); ++r) {
      const auto& [wave, modes] = target_runs[r];
      const WavefrontTracer vectorised(compiled, settings, wave, modes, WavefrontStages::Auto);
      ASSERT_TRUE(vectorised.vectorised()) << vectorised.scalar_reason();
      std::vector<FilmSample> a(pixels * count);
      vectorised.render_batch(0, count, a);
      const std::vector<FilmSample>& b = expected[std::min(r, expected.size() - 1)];
      std::size_t differ = 0;
      for (std::size_t i = 0; i < a.size(); ++i)
        differ += std::memcmp(&a[i].L, &b[i].L, sizeof(Spectrum)) != 0 || a[i].film != b[i].film ||
                  a[i].rays != b[i].rays || a[i].hits != b[i].hits;
      EXPECT_EQ(differ, 0u) << "of " << a.size() << " samples, SIMD target " << simd_target_name(target)
                            << ", wave size " << wave << ", camera rays " << ray_batch_mode_name(modes.camera);
    }
  }
}

std::vector<VectorCase> vector_cases() {
  std::vector<VectorCase> cases;
  for (const char* s : {"", "penumbra-box.json", "penumbra-emissive-polygon.json", "furnace-box.json",
                        "white-sphere-emissive-room.json"})
    for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf}) cases.push_back({s, st});
  cases.push_back({"", Strategy::Mis, 0.2f, 0});
  cases.push_back({"", Strategy::LightBsdf, 0.0f, 0});
  for (Strategy st : {Strategy::Mis, Strategy::LightBsdf}) {
    cases.push_back({"", st, 0.0f, 0, false, true});
    cases.push_back({"white-sphere-emissive-room.json", st, 0.0f, -1, false, true});
  }
  cases.push_back({"", Strategy::Mis, 0.0f, -1, true});  // thin lens
  for (Strategy st : {Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"", st, 0.0f, -1, false, false, true});
  cases.push_back({"white-sphere-emissive-room.json", Strategy::Mis, 0.0f, -1, false, false, true});
  for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"", st, 0.0f, 0, false, false, false, true});
  cases.push_back({"white-sphere-emissive-room.json", Strategy::Mis, 0.0f, 0, false, false, false, true});
  // zsobol: every slot of a vertex (film, lens, light choice and point, technique, direction, roulette); with
  // 2 or 8 spp the permuted index has an odd number of bits (its lone lowest bit).
  for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"", st, 0.0f, 0, false, false, false, false, true});
  cases.push_back({"", Strategy::Mis, 0.0f, -1, true, false, false, false, true});  // thin lens
  cases.push_back({"", Strategy::LightBsdf, 0.0f, 0, true, false, false, false, true, 2});
  cases.push_back({"", Strategy::Mis, 0.0f, 0, false, false, false, false, true, 8});
  cases.push_back({"white-sphere-emissive-room.json", Strategy::LightBsdf, 0.0f, 0, false, true, true, false, true});
  // The light BVH: its pick in sample_lights, its share for the MIS weight of emission found by a ray; more than
  // 16 lights (a deeper tree), off-axis, one-sided, under zsobol.
  for (Strategy st : {Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"", st, 0.0f, 0, false, false, false, false, false, 0, true});
  cases.push_back({"white-sphere-emissive-room.json", Strategy::Mis, 0.0f, 0, false, true, true, false, false, 0, true});
  cases.push_back({"white-sphere-emissive-room.json", Strategy::LightBsdf, 0.0f, -1, false, false, true, true, false, 0, true});
  cases.push_back({"", Strategy::LightBsdf, 0.0f, 0, false, true, true, false, true, 0, true});
  // Materials shaded by core's Surfel between the lanes' steps: Disney (metallic; sheen and clearcoat), and Lambert
  // through the closure (--general-shading); a glass box and a mirror wall, shaded in the lanes.
  for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"materials", st, 0.0f, 0});
  cases.push_back({"materials", Strategy::Mis, 0.2f, 0});
  cases.push_back({"materials", Strategy::Mis, 0.0f, 0, false, true, false, true});
  cases.push_back({"materials", Strategy::LightBsdf, 0.0f, 0, false, false, true, false, true, 0, true});
  cases.push_back({"", Strategy::Mis, 0.0f, 0, false, false, false, false, false, 0, false, true});
  // Shapes with a shading frame of their own (vertex normals, tangents), made by core, shaded in the lanes
  // (kFramed): Lambert, and a Disney plastic under a shading normal; more than 16 shapes (gathered) too.
  for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"smooth", st, 0.0f, 0});
  cases.push_back({"smooth", Strategy::Mis, 0.0f, 0, false, true, false, true});
  cases.push_back({"smooth", Strategy::LightBsdf, 0.0f, -1, false, false, true, false, true});
  cases.push_back({"tangents", Strategy::Mis, 0.0f, 0});
  // Tangent frames made in the lanes: on instances (turned, mirrored, sheared) about vertex normals, and on a
  // flat mesh turned inside out.
  for (Strategy st : {Strategy::Bsdf, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"tangents-instanced", st, 0.0f, 0});
  cases.push_back({"tangents-instanced", Strategy::Mis, 0.0f, -1, true, true, false, true, true, 0, true});
  for (Strategy st : {Strategy::Bsdf, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"smooth-plastic", st, 0.0f, 0});
  cases.push_back({"smooth-plastic", Strategy::Mis, 0.0f, -1, true, true, true, true, true, 0, true});
  // Smooth glass and a smooth mirror: impulses in a frame of their own (vertex normals), in the lanes.
  for (Strategy st : {Strategy::Bsdf, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"smooth-impulses", st, 0.0f, 0});
  cases.push_back({"smooth-impulses", Strategy::Mis, 0.0f, -1, true, true, true, true, true, 0, true});
  // Lights in the lanes beside the Cornell box's triangles: the sky (an environment image, a constant environment,
  // a sun disk) and sphere lights sampled by area (seen from outside: "bulb"; from inside: the rooms of
  // mirror-sphere-gray-room and white-sphere-emissive-room).
  for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"envmap", st, 0.0f, 0});
  for (const char* s : {"sphere-in-environment.json", "sun-disk-plane.json", "glass-sphere-tinted.json",
                        "rough-conductor-sphere.json", "mirror-sphere-gray-room.json", "furnace-sphere.json", "bulb"})
    cases.push_back({s, Strategy::Mis, 0.0f, 0});
  cases.push_back({"bulb", Strategy::LightBsdf, 0.0f, 0, false, true, false, true, true});
  for (Strategy st : {Strategy::Light, Strategy::Mis})
    cases.push_back({"", st, 0.0f, 0, false, false, false, false, false, 0, false, false, true});
  cases.push_back({"materials", Strategy::Mis, 0.0f, 0, false, false, false, false, false, 0, true, false, true});
  // Solid-angle sampling in the lanes' double halves: spherical triangles (the box's lamp, cut into 16 and turned
  // off the axes when crowded and tilted), a sphere's cone seen from outside ("bulb") and, from inside the emitting
  // spheres of the rooms, the fallback to area; under power and the BVH, both samplers, every strategy that samples
  // lights.
  cases.push_back({"", Strategy::LightBsdf, 0.0f, 0, true, true, true, true, true, 0, true, false, true});
  for (Strategy st : {Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"bulb", st, 0.0f, 0, false, false, false, false, false, 0, false, false, true});
  cases.push_back({"bulb", Strategy::Mis, 0.0f, -1, true, true, true, false, true, 0, true, false, true});
  for (const char* s : {"white-sphere-emissive-room.json", "mirror-sphere-gray-room.json"})
    cases.push_back({s, Strategy::Mis, 0.0f, 0, false, false, false, false, false, 0, false, false, true});
  cases.push_back({"bulb", Strategy::Mis, 0.0f, 0, false, false, true, false, false, 0, true});
  // Disney surfaces shaded in the lanes in the geometric normal's frame beside one in its own (tangents); energy
  // compensation's tables gathered in the lanes (a coated sphere; the materials' box with an anisotropic,
  // compensated lacquer).
  for (Strategy st : {Strategy::Bsdf, Strategy::Mis}) cases.push_back({"framed-velvet", st, 0.0f, 0});
  cases.push_back({"coated-sphere-compensated.json", Strategy::Mis, 0.0f, 0});
  cases.push_back({"compensated", Strategy::Mis, 0.0f, 0});
  cases.push_back({"compensated", Strategy::LightBsdf, 0.0f, 0, false, true, false, false, true});
  // Textures (albedo, Disney parameters, a normal map, a mirror's reflectance, an emitter's radiance), read by
  // CompiledScene::resolve with each path's ray cone (and at light samples by LightSampler::emission_at_point).
  for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"textured", st, 0.0f, 0});
  cases.push_back({"textured", Strategy::Mis, 0.0f, -1, true, true, false, true, true});
  // A normal-mapped mirror with a textured reflectance, and glass with textured tints under a normal map, shaded
  // in the lanes from the frame and SurfaceParams core's resolve gives the hit.
  for (Strategy st : {Strategy::Bsdf, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"textured-impulses", st, 0.0f, 0});
  cases.push_back({"textured-impulses", Strategy::Mis, 0.0f, -1, true, true, false, true, true, 0, true});
  // Textured meshes whose hits the lanes resolve, core reading only the texels (kTexturedHits): without texture
  // coordinates, with vertex normals, on instances (turned, mirrored, sheared); Lambert and Disney.
  for (Strategy st : {Strategy::Bsdf, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"textured-meshes", st, 0.0f, 0});
  cases.push_back({"textured-meshes", Strategy::Mis, 0.0f, -1, true, true, false, true, true, 0, true});
  // The emitter's radiance texture read at light samples drawn in the lanes, by area or in solid angle.
  for (Strategy st : {Strategy::Light, Strategy::LightBsdf})
    cases.push_back({"textured", st, 0.0f, 0, false, false, false, false, false, 0, false, false, true});
  cases.push_back({"textured", Strategy::Mis, 0.0f, 0, false, true, false, false, true, 0, true, false, true});
  // Disney's glossy lobes sampled by cosine-power lobes (bsdf_sampling cospow): flat, under a shading normal,
  // energy-compensated and textured; off the axes, under zsobol and the BVH.
  const auto cospow = [&](VectorCase c) {
    c.cospow = true;
    cases.push_back(c);
  };
  for (Strategy st : {Strategy::Bsdf, Strategy::Mis, Strategy::LightBsdf}) cospow({"materials", st, 0.0f, 0});
  cospow({"materials", Strategy::Mis, 0.2f, 0, false, true, false, false, true, 0, true});
  cospow({"smooth-plastic", Strategy::Mis, 0.0f, 0});
  cospow({"compensated", Strategy::Mis, 0.0f, 0});
  cospow({"textured", Strategy::LightBsdf, 0.0f, 0});
  // Delta lights (a point, a spot and a directional light): two shadow rays a path, interleaved in path order.
  for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"delta", st, 0.0f, 0});
  cases.push_back({"delta", Strategy::LightBsdf, 0.0f, -1, true, true, true, true, true, 0, true});
  // Every kind of light at once: delta lights, the sky, an emitter in a group, solid angle.
  for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"every-light", st, 0.0f, 0});
  cases.push_back({"every-light", Strategy::Mis, 0.0f, 0, false, false, false, false, true, 0, false, false, true});
  cases.push_back({"envmap-sun-plane.json", Strategy::LightBsdf, 0.0f, 0});
  // The sky in the lanes beside triangle lights: an environment of one radiance and two sun disks, one inside the
  // other (sun-disk-plane: a sun alone; furnace-sphere, sphere-in-environment: an environment alone), picked by
  // power or by the light BVH's grid (the sky's share beside the tree's).
  for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"sky", st, 0.0f, 0});
  for (Strategy st : {Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"sky", st, 0.0f, 0, false, false, false, false, false, 0, true});
  cases.push_back({"sky", Strategy::Mis, 0.0f, -1, true, true, false, true, true, 0, true});
  cases.push_back({"sky", Strategy::LightBsdf, 0.0f, 0, false, false, true, false, false, 0, false});
  cases.push_back({"sun-disk-plane.json", Strategy::Light, 0.0f, 0, false, false, false, false, false, 0, true});
  // An environment image in the lanes (its texels drawn by the importance sampler, looked up by escaped rays):
  // alone over a diffuse sphere and a metal ground ("envmap", above), with a sun disk (envmap-sun-plane), and
  // beside triangle lights and two sun disks, by power and by the light BVH.
  for (Strategy st : {Strategy::Bsdf, Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
    cases.push_back({"sky-image", st, 0.0f, 0});
  for (Strategy st : {Strategy::Light, Strategy::Mis})
    cases.push_back({"sky-image", st, 0.0f, 0, false, false, false, false, false, 0, true});
  cases.push_back({"sky-image", Strategy::Mis, 0.0f, -1, true, true, true, true, true, 0, false});
  // A patchy, turned map: rows and cells of density 0 beside the sun disks.
  for (Strategy st : {Strategy::Light, Strategy::Mis}) cases.push_back({"patchy-sky", st, 0.0f, 0});
  cases.push_back({"patchy-sky", Strategy::LightBsdf, 0.0f, 0, false, false, false, false, true, 0, true});
  cases.push_back({"envmap", Strategy::Mis, 0.0f, 0, false, false, false, false, true, 0, true});
  cases.push_back({"envmap-sun-plane.json", Strategy::Mis, 0.0f, 0});
  // Strategy cosine: every surface scattered by core's Surfel::scatter_cosine (impulses by scatter).
  for (const char* sc : {"", "materials", "textured"}) cases.push_back({sc, Strategy::Cosine, 0.0f, 0});
  // Alpha: every ray's key made in the lanes (camera, continuation and shadow rays, compacted with the path).
  for (Strategy st : {Strategy::Bsdf, Strategy::Mis, Strategy::LightBsdf}) cases.push_back({"alpha", st, 0.0f, 0});
  cases.push_back({"alpha", Strategy::Mis, 0.0f, -1, true, true, false, false, true, 0, true});
  cases.push_back({"penumbra-alpha.json", Strategy::Mis, 0.0f, 0});
  cases.push_back({"penumbra-cutout.json", Strategy::LightBsdf, 0.0f, 0});
  // Instances: hits placed by CompiledScene::resolve, path by path.
  for (Strategy st : {Strategy::Bsdf, Strategy::Mis, Strategy::LightBsdf}) cases.push_back({"instanced", st, 0.0f, 0});
  cases.push_back({"instanced", Strategy::Mis, 0.0f, 0, false, true, false, true, true, 0, true});
  cases.push_back({"white-sphere-emissive-room.json", Strategy::LightBsdf, 0.0f, 0, false, true, false, true, false, 0,
                   false, true});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Scenes, VectorStages, testing::ValuesIn(vector_cases()),
                         [](const testing::TestParamInfo<VectorCase>& p) {
                           std::string s = (p.param.scene.empty() ? std::string("cornell") : p.param.scene) + "_" +
                                           strategy_name(p.param.strategy) + (p.param.min_pdf > 0 ? "_min_pdf" : "") +
                                           (p.param.rr_depth >= 0 ? "_rr" + std::to_string(p.param.rr_depth) : "") +
                                           (p.param.tilted ? "_tilted" : "") + (p.param.thin_lens ? "_thin_lens" : "") +
                                           (p.param.crowded ? "_crowded" : "") + (p.param.one_sided ? "_one_sided" : "") +
                                           (p.param.zsobol ? "_zsobol" : "") +
                                           (p.param.spp > 0 ? "_spp" + std::to_string(p.param.spp) : "") +
                                           (p.param.bvh ? "_bvh" : "") +
                                           (p.param.general_shading ? "_general_shading" : "") +
                                           (p.param.solid_angle ? "_solid_angle" : "") +
                                           (p.param.cospow ? "_cospow" : "");
                           for (char& ch : s)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return s;
                         });

// What the stages leave to core, path by path, as `pathlab render` names
// it: no light sample under solid-angle sampling, nor with an emitter placed
// by an instance beside delta lights and the sky; of a textured emitter's
// light samples, only the texel; of hits on every textured shape (spheres
// and emitters among them), only the texels.
TEST(Wavefront, StagesNameWhatCoreDoesPathByPath) {
  const auto describe = [](Scene scene) {
    const RenderSettings settings = scene.render;
    const CompiledScene compiled(std::move(scene));
    return WavefrontTracer(compiled, settings).stages_description();
  };
  Scene solid_angle = builtin_cornell_box();
  solid_angle.render.light_sampling = LightSampling::SolidAngle;
  const std::string plain = describe(solid_angle);
  EXPECT_EQ(plain.find("by core"), std::string::npos) << plain;
  const std::string every = describe(cornell_with_every_light());
  EXPECT_EQ(every.find("light samples"), std::string::npos) << every;
  const std::string textured = describe(test::cornell_with_textures());
  EXPECT_NE(textured.find("the emission textures' reads at light samples"), std::string::npos) << textured;
  EXPECT_EQ(textured.find("the light samples ("), std::string::npos) << textured;
  EXPECT_EQ(textured.find("the texture reads"), std::string::npos) << textured;
  EXPECT_NE(textured.find("the texels at hits on 'floor', 'walls', 'red', 'mirror', 'disney', 'ball' and 'light' ("), std::string::npos)
      << textured;
}

// Every kind of scene runs the vectorised stages at a vector SIMD target
// (what the lanes do not do, core does path by path between them); the
// scalar target runs the scalar stages.
TEST(Wavefront, VectorisedForEverySceneAtAVectorTarget) {
  auto vectorised = [](Scene scene, Strategy strategy, bool general = false) {
    scene.render.strategy = strategy;
    scene.render.force_general_shading = general;
    const RenderSettings settings = scene.render;
    const CompiledScene compiled(std::move(scene));
    return WavefrontTracer(compiled, settings).vectorised();
  };
  const Scene cornell = builtin_cornell_box();
  const bool any = vector_stages::cpu_supported();
  EXPECT_EQ(vectorised(cornell, Strategy::Mis), any);
  {
    const SimdChoice scalar(SimdTarget::Scalar);
    EXPECT_FALSE(vectorised(cornell, Strategy::Mis));
  }

  Scene zsobol = cornell;  // its Sobol' points are drawn in the lanes too
  zsobol.render.sampler = SamplerKind::ZSobol;
  EXPECT_EQ(vectorised(zsobol, Strategy::Mis), any);

  EXPECT_EQ(vectorised(cornell, Strategy::Cosine), any);  // scatter_cosine by core
  // Materials the lanes do not shade are shaded by core's Surfel between them.
  EXPECT_EQ(vectorised(cornell, Strategy::Mis, true), any);  // --general-shading
  EXPECT_EQ(vectorised(cornell_with_materials(), Strategy::Mis), any);
  // Shading frames of their own, shaded in the lanes: of vertex normals made there, of tangents by core.
  EXPECT_EQ(vectorised(cornell_with_tangents(), Strategy::Mis), any);
  EXPECT_EQ(vectorised(test::cornell_with_smooth_sphere(), Strategy::Mis), any);
  // Lights the lanes do not sample (solid-angle sampling) are sampled by core's LightSampler between them; the
  // sky (an environment, an image, sun disks) and sphere lights in them.
  Scene solid_angle = cornell;
  solid_angle.render.light_sampling = LightSampling::SolidAngle;
  EXPECT_EQ(vectorised(solid_angle, Strategy::Mis), any);
  const auto analytic = std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes";
  Scene sphere_light = cornell;
  Shape bulb;
  bulb.kind = Shape::Kind::Sphere;
  bulb.center = vec3(0.0f, 1.0f, 0.0f);
  bulb.radius = 0.1f;
  for (std::uint32_t m = 0; m < sphere_light.materials.size(); ++m)
    if (sphere_light.materials[m].emits()) bulb.material = m;
  ASSERT_TRUE(sphere_light.materials[bulb.material].emits());
  sphere_light.shapes.push_back(bulb);
  EXPECT_EQ(vectorised(sphere_light, Strategy::Mis), any);
  // Delta lights: a second light sample per path, by core's LightSampler.
  Scene point_light = cornell;
  point_light.delta_lights.push_back({vec3(0.0f, 1.0f, 0.0f), Spectrum(1.0f)});
  EXPECT_EQ(vectorised(point_light, Strategy::Mis), any);
  Scene spot = cornell, sun = cornell;
  spot.delta_lights.push_back({vec3(0.0f, 1.0f, 0.0f), Spectrum(1.0f), DeltaLight::Kind::Spot, vec3(0, -1, 0), 0.5f, 0.9f});
  sun.delta_lights.push_back({vec3(0.0f), Spectrum(1.0f), DeltaLight::Kind::Directional, vec3(0, -1, 0), 0.0f, 0.0f});
  EXPECT_EQ(vectorised(spot, Strategy::Mis), any);
  EXPECT_EQ(vectorised(sun, Strategy::Mis), any);
  EXPECT_EQ(vectorised(test::cornell_with_alpha(), Strategy::Mis), any);  // each ray carries its alpha key
  EXPECT_EQ(vectorised(load_scene(analytic / "sphere-in-environment.json"), Strategy::Mis), any);  // environment
  Scene envmap = cornell;  // triangle lights and an environment image
  envmap.environment_map = load_scene(analytic / "envmap-direct.json").environment_map;
  EXPECT_EQ(vectorised(envmap, Strategy::Mis), any);
  EXPECT_EQ(vectorised(load_scene(analytic / "mirror-sphere-gray-room.json"), Strategy::Mis), any);  // a sphere light
  EXPECT_EQ(vectorised(load_scene(std::filesystem::path(PATHLAB_SOURCE_DIR) / "scenes" / "materials.json"),
                       Strategy::Mis),
            any);  // an environment, Disney, glass
  EXPECT_EQ(vectorised(test::cornell_with_textures(), Strategy::Mis), any);  // textures read by core, path by path
  EXPECT_EQ(vectorised(test::cornell_with_instances(), Strategy::Mis), any);  // hits placed in the lanes
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

// Each stage's clock runs (both kinds of stages), and the stages and
// Embree's batches together take no more than the waves' time.
TEST(Wavefront, TimesEveryStage) {
  Scene scene = test::small_cornell(16, 4, FilterKind::Box);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  for (WavefrontStages stages : {WavefrontStages::Auto, WavefrontStages::Scalar}) {
    const WavefrontTracer tracer(compiled, settings, WavefrontTracer::kDefaultWaveSize, {}, stages);
    Film film(16, 16, FilterKind::Box);
    render(tracer, film);
    const WavefrontTimes t = tracer.times();
    double sum = t.query_seconds();
    for (int k = 0; k < kWavefrontStages; ++k) {
      EXPECT_GT(t.stage_seconds[k], 0.0) << wavefront_stage_name(static_cast<WavefrontStage>(k)) << ", "
                                         << (stages == WavefrontStages::Auto ? "auto" : "scalar");
      sum += t.stage_seconds[k];
    }
    EXPECT_LE(sum, t.waves_seconds * (1.0 + 1e-9));
  }
}

}  // namespace
}  // namespace pathlab
