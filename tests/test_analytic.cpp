// Every analytic scene, with the reference tracer and every strategy, passes
// its check at its own sample count (label "stat"); the models refuse scenes
// that break their assumptions and follow edits of their parameters.
#include "tests/check_util.h"
#include "tests/stat_util.h"
#include "tests/test_scenes.h"

#include "core/error.h"
#include "wavefront/wavefront_tracer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace pathlab {
namespace {

struct Case {
  std::string scene;
  Strategy strategy;
  bool wavefront;
  LightSampling light_sampling = LightSampling::Area;
};

class AnalyticScenes : public testing::TestWithParam<Case> {};

TEST_P(AnalyticScenes, PassCheck) {
  Scene scene = test::load_with_strategy(GetParam().scene, GetParam().strategy);
  scene.render.light_sampling = GetParam().light_sampling;
  // The cases of one scene differ only in tracer, strategy, light sampling
  // and sample count, none of which the model reads: one expected image
  // serves them all.
  static std::map<std::string, ExpectedImage> expected_of;
  auto it = expected_of.find(GetParam().scene);
  if (it == expected_of.end()) it = expected_of.emplace(GetParam().scene, test::expected_image_of(scene)).first;
  const CheckResult r = GetParam().wavefront ? test::run_check<WavefrontTracer>(std::move(scene), {}, &it->second)
                                             : test::run_check(std::move(scene), {}, &it->second);
  EXPECT_TRUE(r.pixels_pass) << r.failing << " pixel-channels beyond " << r.z_threshold << ", worst z "
                             << r.worst.front().z << " at (" << r.worst.front().x << ", " << r.worst.front().y << ")";
  EXPECT_TRUE(r.bias_pass) << "bias " << r.bias << " +- " << r.bias_se;
}

std::vector<Case> all_cases() {
  std::vector<Case> cases;
  for (const std::string& name : test::analytic_scene_names())
    for (Strategy s : test::kAllStrategies)
      for (bool wavefront : {false, true}) cases.push_back({name, s, wavefront});
  // Solid-angle light sampling (a representative subset: triangle lights
  // seen near and far, a textured emitter, a room-sized sphere light seen
  // from inside) with the strategies that sample lights.
  for (const char* name : {"penumbra-box.json", "textured-room.json", "white-sphere-emissive-room.json"})
    for (Strategy s : {Strategy::Light, Strategy::Mis, Strategy::LightBsdf})
      for (bool wavefront : {false, true}) cases.push_back({name, s, wavefront, LightSampling::SolidAngle});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Reference, AnalyticScenes, testing::ValuesIn(all_cases()),
                         [](const testing::TestParamInfo<Case>& p) {
                           return test::analytic_case_name(p.param.scene, p.param.strategy, p.param.wavefront,
                                                           p.param.light_sampling);
                         });

// Editing the parameters the models read keeps the check passing.
TEST(AnalyticEdits, FurnaceFollowsAlbedoEmissionAndDepth) {
  for (const auto& [albedo, Le, depth] : {std::tuple{0.3f, 2.0f, 0}, {0.9f, 0.5f, 7}, {0.5f, 1.0f, -1}}) {
    Scene s = load_scene(test::analytic_scene("furnace-sphere.json"));
    s.materials[0].albedo = Spectrum(albedo);
    s.materials[0].emission = Spectrum(Le);
    s.render.max_depth = depth;
    EXPECT_TRUE(test::run_check(std::move(s)).pass) << albedo << " " << Le << " " << depth;
  }
}

TEST(AnalyticEdits, SphereFollowsAlbedoRadiusAndRoom) {
  Scene s = load_scene(test::analytic_scene("white-sphere-emissive-room.json"));
  for (Material& m : s.materials) {
    if (m.type == MaterialType::Diffuse) m.albedo = Spectrum(0.2f, 0.9f, 0.5f);
    if (m.type == MaterialType::Emissive) m.emission = Spectrum(3.0f, 0.5f, 1.0f);
  }
  s.shapes[0].radius = 0.6f;
  s.shapes[0].center = vec3(0.3f, -0.2f, 0.0f);
  EXPECT_TRUE(test::run_check(std::move(s)).pass);
}

TEST(AnalyticEdits, AModelThatIgnoredAnEditWouldFail) {
  // Render with albedo 0.2 but build the model from the file's albedo: the
  // check must see the difference (guards against a model that reads
  // nothing from the scene).
  Scene s = load_scene(test::analytic_scene("furnace-sphere.json"));
  const auto model = make_analytic_model(s);
  s.materials[0].albedo = Spectrum(0.2f);
  const RenderSettings settings = s.render;
  const CompiledScene compiled(std::move(s));
  const ReferenceTracer tracer(compiled, settings);
  Film film(compiled.scene().film.width, compiled.scene().film.height, compiled.scene().film.filter);
  render(tracer, film);
  EXPECT_FALSE(check_against_expected(film, expected_image(*model, compiled.camera(), compiled.scene().film)).pass);
}

// The same rectangle as a light (found by light sampling) and as a plain
// emissive surface (found only by BSDF sampling): the latter's render passes
// against the former scene's expected image, so the two agree with each other
// through the one model. (Comparing the two renders directly would need the
// checker's variance floors twice over.)
TEST(AnalyticPenumbra, EmissivePolygonMatchesTheLightsExpectedImage) {
  const Scene light_scene = load_scene(test::analytic_scene("penumbra-box.json"));
  Scene polygon_scene = load_scene(test::analytic_scene("penumbra-emissive-polygon.json"));
  ASSERT_TRUE(light_scene.materials[light_scene.shapes[1].material].sampled_as_light);
  ASSERT_FALSE(polygon_scene.materials[polygon_scene.shapes[1].material].sampled_as_light);
  const auto model = make_analytic_model(light_scene);
  for (Strategy strategy : {Strategy::Mis, Strategy::Light}) {
    polygon_scene.render.strategy = strategy;
    const RenderSettings settings = polygon_scene.render;
    const CompiledScene compiled{Scene(polygon_scene)};
    EXPECT_EQ(compiled.lights().area_light_count(), 0u);
    const ReferenceTracer tracer(compiled, settings);
    Film film(compiled.scene().film.width, compiled.scene().film.height, compiled.scene().film.filter);
    render(tracer, film);
    EXPECT_TRUE(check_against_expected(film, expected_image(*model, compiled.camera(), compiled.scene().film)).pass)
        << strategy_name(strategy);
  }
}

// The sun disk model's own radiance against its closed form: a disk of
// angular radius alpha giving irradiance E at normal incidence has radiance
// E / (pi sin^2 alpha), the cosine-weighted solid angle of the cap being
// pi sin^2 alpha; nothing outside the cap. (The plane's pixels do not depend
// on it: only a camera that sees the sun would, so it is tested here.)
TEST(AnalyticSun, DiskRadianceIsIrradianceOverPiSinSquaredAlpha) {
  const Scene s = load_scene(test::analytic_scene("sun-disk-plane.json"));
  const auto model = make_analytic_model(s);
  const DeltaLight& sun = s.delta_lights[0];
  const glm::dvec3 to_sun = -glm::normalize(glm::dvec3(sun.direction));
  const double alpha = sun.angular_radius, sin_alpha = std::sin(alpha);
  const vec3 above(0.0f, 2.0f, 0.0f);
  const Spectrum L = model->radiance(Ray{above, vec3(to_sun)});
  for (int c = 0; c < 3; ++c) {
    const double expected = double(sun.intensity[c]) / (M_PI * sin_alpha * sin_alpha);
    EXPECT_NEAR(L[c], expected, 1e-6 * expected) << "channel " << c;
  }
  // Just inside and just outside the cap's rim (rotated about the z axis, perpendicular to to_sun).
  auto tilted = [&](double angle) {
    const double c = std::cos(angle), sn = std::sin(angle);
    return vec3(glm::normalize(glm::dvec3(c * to_sun.x - sn * to_sun.y, sn * to_sun.x + c * to_sun.y, to_sun.z)));
  };
  EXPECT_GT(model->radiance(Ray{above, tilted(0.99 * alpha)}).x, 0.0f);
  EXPECT_EQ(model->radiance(Ray{above, tilted(1.01 * alpha)}), Spectrum(0.0f));
}

void expect_refused(const std::string& scene_name, const std::function<void(Scene&)>& edit, const std::string& words) {
  Scene s = load_scene(test::analytic_scene(scene_name));
  edit(s);
  try {
    make_analytic_model(s);
    ADD_FAILURE() << "accepted a scene that breaks the model: " << words;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(scene_name), std::string::npos) << e.what();
  }
}

TEST(AnalyticRefusals, FurnaceAssumptions) {
  expect_refused("furnace-sphere.json", [](Scene& s) { s.shapes[0].flip_normals = false; }, "faces outwards");
  expect_refused("furnace-sphere.json", [](Scene& s) { s.camera.position = vec3(0, 0, 3); }, "camera must be inside");
  expect_refused("furnace-sphere.json", [](Scene& s) { s.materials[0].emission = Spectrum(0.0f); }, "must emit");
  expect_refused("furnace-sphere.json", [](Scene& s) { s.materials[0].type = MaterialType::Mirror; }, "diffuse");
  expect_refused("furnace-sphere.json", [](Scene& s) { s.delta_lights.push_back({vec3(0.0f), Spectrum(1.0f)}); }, "delta lights");
  expect_refused("furnace-sphere.json", [](Scene& s) { s.render.max_depth = -1; s.materials[0].albedo = Spectrum(1.0f); }, "below 1");
  expect_refused("furnace-box.json", [](Scene& s) { s.shapes[0].mesh.triangles.pop_back(); }, "closed");
  expect_refused("furnace-box.json", [](Scene& s) { s.camera.aperture_radius = 0.1f; }, "pinhole");
  expect_refused("furnace-box.json", [](Scene& s) { s.analytic = "furnac"; }, "did you mean 'furnace'");
}

TEST(AnalyticRefusals, PenumbraAssumptions) {
  // shapes: 0 ground, 1 lamp, 2 box
  expect_refused("penumbra-box.json", [](Scene& s) { s.shapes[2].mesh.positions[0].y += 5.0f; }, "closed convex mesh");
  expect_refused("penumbra-box.json", [](Scene& s) { for (vec3& p : s.shapes[2].mesh.positions) p.y += 1.5f; }, "strictly between");
  expect_refused("penumbra-box.json", [](Scene& s) { s.shapes[1].mesh.positions[0].y -= 0.3f; }, "planar");
  expect_refused("penumbra-box.json", [](Scene& s) { s.shapes.push_back(s.shapes[2]); }, "at most one black occluder");
  expect_refused("penumbra-box.json", [](Scene& s) { s.environment = Spectrum(1.0f); }, "environment");
  expect_refused("penumbra-box.json", [](Scene& s) { s.materials[s.shapes[0].material].type = MaterialType::Mirror; }, "diffuse");
}

TEST(AnalyticRefusals, SphereAssumptions) {
  expect_refused("white-sphere-emissive-room.json", [](Scene& s) { s.shapes[1].flip_normals = false; }, "faces outwards");
  expect_refused("white-sphere-emissive-room.json", [](Scene& s) { s.shapes[0].center = vec3(9, 0, 0); }, "sphere must be inside");
  expect_refused("mirror-sphere-gray-room.json", [](Scene& s) { s.render.max_depth = 5; }, "perfect mirror");
  expect_refused("mirror-sphere-gray-room.json", [](Scene& s) { s.materials[0].albedo = Spectrum(0.9f); }, "perfect mirror");
  expect_refused("sphere-in-environment.json", [](Scene& s) { s.environment.reset(); }, "environment or a closed");
  // An environment image is uniform only when constant.
  expect_refused("white-sphere-constant-envmap.json", [](Scene& s) {
    s.environment_map = load_scene(test::analytic_scene("envmap-direct.json")).environment_map;
  }, "not constant");
}

TEST(AnalyticRefusals, EnvironmentMapAssumptions) {
  expect_refused("envmap-mirror-sphere.json", [](Scene& s) { s.environment_map.reset(); }, "needs an environment image");
  expect_refused("envmap-mirror-sphere.json", [](Scene& s) { s.materials[0].type = MaterialType::Diffuse; }, "must be a mirror");
  expect_refused("envmap-diffuse-plane.json", [](Scene& s) { s.shapes[0].mesh.positions[0].y += 0.5f; }, "face the environment's up");
  expect_refused("envmap-diffuse-plane.json", [](Scene& s) { s.camera.position.y = -1.0f; }, "camera must be above");
  expect_refused("envmap-diffuse-plane.json", [](Scene& s) { s.materials[0].type = MaterialType::Mirror; }, "two-sided diffuse");
  expect_refused("envmap-mirror-sphere.json", [](Scene& s) { s.shapes.push_back(s.shapes[0]); }, "at most one shape");
  expect_refused("envmap-mirror-sphere.json", [](Scene& s) { s.delta_lights.push_back({vec3(0.0f), Spectrum(1.0f)}); },
                 "delta lights");
  expect_refused("penumbra-box.json", [](Scene& s) {
    s.environment_map = load_scene(test::analytic_scene("envmap-direct.json")).environment_map;
  }, "environment");
}

TEST(AnalyticRefusals, PlaneUnderSunAssumptions) {
  expect_refused("sun-disk-plane.json", [](Scene& s) { s.delta_lights[0].angular_radius = 0.0f; }, "angular_diameter");
  expect_refused("sun-disk-plane.json", [](Scene& s) { s.environment = Spectrum(1.0f); }, "environment");
  expect_refused("sun-disk-plane.json", [](Scene& s) { s.delta_lights[0].angular_radius = 1.2f; }, "whole sun disk");
  expect_refused("sun-disk-plane.json", [](Scene& s) { s.camera.position.y = -1.0f; }, "sunny side");
  expect_refused("sun-disk-plane.json", [](Scene& s) { s.materials[0].one_sided = true; }, "two-sided");
  expect_refused("sun-disk-plane.json", [](Scene& s) { s.delta_lights.push_back({vec3(0.0f, 3.0f, 0.0f), Spectrum(1.0f)}); },
                 "exactly one light");
  expect_refused("envmap-sun-plane.json", [](Scene& s) { s.delta_lights[0].angular_radius = 0.0f; }, "delta lights");
  expect_refused("envmap-sun-plane.json", [](Scene& s) { s.delta_lights[0].direction = vec3(0, 0.2f, -1); },
                 "wholly above the plane");
}

// The sun's real size, 0.53 degrees: found by light sampling only (BSDF
// sampling would hit it about once in 10^5 samples, so cosine and bsdf are
// not run), the plane still shows a E cos theta / pi, in both tracers.
TEST(AnalyticSunDisk, RealSunThroughLightSampling) {
  for (Strategy strategy : {Strategy::Mis, Strategy::Light, Strategy::LightBsdf})
    for (bool wavefront : {false, true}) {
      Scene s = test::load_with_strategy("sun-disk-plane.json", strategy);
      s.delta_lights[0].angular_radius = glm::radians(0.265f);
      const CheckResult r = wavefront ? test::run_check<WavefrontTracer>(std::move(s)) : test::run_check(std::move(s));
      EXPECT_TRUE(r.pass) << strategy_name(strategy) << (wavefront ? " wavefront" : " reference") << ": bias " << r.bias
                          << " +- " << r.bias_se << ", " << r.failing << " pixel-channels fail";
    }
}

// The expected image of a piecewise-constant map has edges wherever a pixel
// straddles a texel boundary. Its midpoint quadrature (expected_image.h) must
// be far more accurate there than the check's statistical tolerance (|z| up
// to the Sidak threshold times the pixel's noise), or the check would lose
// its power on those pixels: the reported quadrature error stays below a
// tenth of that tolerance, everywhere (noise: the render's own variance of
// the mean, or the footprint's floor where that is larger, as check.h does).
TEST(AnalyticEnvironmentMap, QuadratureFarBelowTheNoise) {
  for (const char* name : {"envmap-direct.json", "envmap-mirror-sphere.json"}) {
    const Scene scene = load_scene(test::analytic_scene(name));
    const auto model = make_analytic_model(scene);
    const RenderSettings settings = scene.render;
    const CompiledScene compiled{Scene(scene)};
    const ReferenceTracer tracer(compiled, settings);
    Film film(scene.film.width, scene.film.height, scene.film.filter, FilmMoments::MeanAndVariance);
    render(tracer, film);
    const ExpectedImage expected = expected_image(*model, compiled.camera(), scene.film);
    const Image variance = film.variance_of_mean();
    const double n = 3.0 * scene.film.width * scene.film.height;
    const double tolerance = normal_two_sided_quantile(-std::expm1(std::log1p(-CheckOptions{}.alpha) / n));
    double worst = 0.0;
    for (int y = 0; y < scene.film.height; ++y)
      for (int x = 0; x < scene.film.width; ++x)
        for (int c = 0; c < 3; ++c) {
          const double noise = std::sqrt(std::max(double(variance.at(x, y)[c]),
                                                  double(expected.footprint_variance.at(x, y)[c]) / settings.spp));
          if (noise > 0.0) worst = std::max(worst, double(expected.quadrature_error.at(x, y)[c]) / (tolerance * noise));
          else  // the whole footprint in one texel: nothing to miss but rounding
            EXPECT_LE(expected.quadrature_error.at(x, y)[c], 1e-6f * expected.mean.at(x, y)[c]) << name << " " << x << "," << y;
        }
    EXPECT_LT(worst, 0.1) << name;
  }
}

}  // namespace
}  // namespace pathlab
