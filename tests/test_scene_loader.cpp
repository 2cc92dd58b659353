// The JSON scene format (core/scene_loader.h): every shape, transform,
// material, light and setting, their defaults, and the location and wording
// of the errors.
#include "core/scene_loader.h"

#include "core/error.h"

#include <glm/gtc/matrix_transform.hpp>
#include "tests/temp_dir.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;

constexpr float kTol = 1e-5f;

// A complete scene text, laid out one key per line so that positions in
// messages are easy to predict. `extra` adds top-level members.
std::string scene_text(const std::string& materials, const std::string& shapes, const std::string& extra = "") {
  return "{\n"
         "  \"pathlab_scene\": 1,\n"
         "  \"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]},\n"
         "  \"materials\": " + materials + ",\n"
         "  \"shapes\": " + shapes + (extra.empty() ? "" : ",\n  " + extra) + "\n}\n";
}

// One light and one white material: enough for any shape list.
const std::string kMaterials =
    R"({"white": {"type": "diffuse", "albedo": [0.8, 0.7, 0.6]}, "lamp": {"type": "emissive", "radiance": 4}})";

std::string shapes_with(const std::string& shape) { return "[" + shape + "]"; }

Scene parse(const std::string& text, const fs::path& file = "scene.json") { return parse_scene(text, file); }

// The InputError message for `text`, or "(no error)".
std::string error_of(const std::string& text, const fs::path& file = "scene.json") {
  try {
    (void)parse_scene(text, file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// "line:col" (1-based, byte column) of the first `needle` in `text`.
std::string where_in(std::string_view text, std::string_view needle) {
  const std::size_t at = text.find(needle);
  EXPECT_NE(at, std::string_view::npos) << needle;
  const std::string_view before = text.substr(0, at);
  const auto line = std::count(before.begin(), before.end(), '\n') + 1;
  const std::size_t line_start = before.rfind('\n') == std::string_view::npos ? 0 : before.rfind('\n') + 1;
  return std::to_string(line) + ":" + std::to_string(at - line_start + 1);
}

// The message is "scene.json:<where>: <pointer>: ..." and contains `problem`.
void expect_error(const std::string& text, const std::string& where, const std::string& pointer,
                  const std::string& problem) {
  const std::string message = error_of(text);
  EXPECT_EQ(message.rfind("scene.json:" + where + ": " + pointer + ": ", 0), 0u) << message;
  EXPECT_NE(message.find(problem), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

void expect_vec(const vec3& got, const vec3& want) {
  EXPECT_NEAR(got.x, want.x, kTol);
  EXPECT_NEAR(got.y, want.y, kTol);
  EXPECT_NEAR(got.z, want.z, kTol);
}

vec3 geometric_normal(const TriangleMesh& mesh, std::size_t tri) {
  const glm::uvec3 t = mesh.triangles[tri];
  const vec3 &a = mesh.positions[t.x], &b = mesh.positions[t.y], &c = mesh.positions[t.z];
  return glm::normalize(glm::cross(b - a, c - a));
}

vec3 centroid(const TriangleMesh& mesh, std::size_t tri) {
  const glm::uvec3 t = mesh.triangles[tri];
  return (mesh.positions[t.x] + mesh.positions[t.y] + mesh.positions[t.z]) / 3.0f;
}

// The single shape of a scene with `shape_json` in it.
Shape only_shape(const std::string& shape_json) {
  const Scene scene = parse(scene_text(kMaterials, shapes_with(shape_json)));
  EXPECT_EQ(scene.shapes.size(), 1u);
  return scene.shapes.empty() ? Shape{} : scene.shapes[0];
}

// ------------------------------------------------------------ defaults

TEST(SceneLoader, MinimalSceneGetsEveryDefault) {
  const Scene s = parse(scene_text(R"({"m": {"type": "diffuse"}})", "[]"), "folder/minimal.json");
  EXPECT_EQ(s.file, fs::path("folder/minimal.json"));
  EXPECT_EQ(s.name, "minimal");
  // Camera.
  expect_vec(s.camera.position, vec3(0, 0, 5));
  expect_vec(s.camera.look_at, vec3(0, 0, 0));
  expect_vec(s.camera.up, vec3(0, 1, 0));
  EXPECT_FLOAT_EQ(s.camera.fov_y_degrees, 40.0f);
  EXPECT_FLOAT_EQ(s.camera.aperture_radius, 0.0f);
  EXPECT_FLOAT_EQ(s.camera.focus_distance, 5.0f);
  // Film.
  EXPECT_EQ(s.film.width, 256);
  EXPECT_EQ(s.film.height, 256);
  EXPECT_EQ(s.film.filter, FilterKind::Box);
  // Render settings.
  EXPECT_EQ(s.render.spp, 16);
  EXPECT_EQ(s.render.max_depth, 8);
  EXPECT_EQ(s.render.rr_depth, 5);
  EXPECT_EQ(s.render.strategy, Strategy::Mis);
  EXPECT_EQ(s.render.seed, 0u);
  // Lights: none, which is worth a warning naming the file.
  EXPECT_TRUE(s.delta_lights.empty());
  EXPECT_FALSE(s.environment.has_value());
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("folder/minimal.json"), std::string::npos) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("no light"), std::string::npos) << s.warnings[0];
}

TEST(SceneLoader, FocusDistanceDefaultsToDistanceToLookAt) {
  const Scene s = parse(R"({"pathlab_scene": 1,
    "camera": {"position": [1, 2, 3], "look_at": [4, 6, 3], "aperture_radius": 0.1},
    "materials": {}, "shapes": []})");
  EXPECT_FLOAT_EQ(s.camera.focus_distance, 5.0f);  // |(3, 4, 0)|
  EXPECT_FLOAT_EQ(s.camera.aperture_radius, 0.1f);
}

TEST(SceneLoader, CameraReadsEveryKey) {
  const Scene s = parse(R"({"pathlab_scene": 1,
    "camera": {"position": [1, 2, 3], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_y": 65,
               "aperture_radius": 0.25, "focus_distance": 2.5},
    "materials": {}, "shapes": []})");
  expect_vec(s.camera.position, vec3(1, 2, 3));
  expect_vec(s.camera.up, vec3(0, 0, 1));
  EXPECT_FLOAT_EQ(s.camera.fov_y_degrees, 65.0f);
  EXPECT_FLOAT_EQ(s.camera.aperture_radius, 0.25f);
  EXPECT_FLOAT_EQ(s.camera.focus_distance, 2.5f);
}

TEST(SceneLoader, RenderSettingsAndFilm) {
  const Scene s = parse(scene_text("{}", "[]",
                                   R"("film": {"resolution": [320, 200], "filter": "bilinear"},
  "render": {"spp": 3, "max_depth": -1, "rr_depth": 0, "strategy": "light+bsdf", "seed": 18446744073709551615})"));
  EXPECT_EQ(s.film.width, 320);
  EXPECT_EQ(s.film.height, 200);
  EXPECT_EQ(s.film.filter, FilterKind::Bilinear);
  EXPECT_EQ(s.render.spp, 3);
  EXPECT_EQ(s.render.max_depth, -1);
  EXPECT_EQ(s.render.rr_depth, 0);
  EXPECT_EQ(s.render.strategy, Strategy::LightBsdf);
  EXPECT_EQ(s.render.seed, 18446744073709551615ull);  // the whole range --seed takes
}

TEST(SceneLoader, EveryStrategyName) {
  const std::pair<const char*, Strategy> names[] = {{"cosine", Strategy::Cosine},
                                                    {"bsdf", Strategy::Bsdf},
                                                    {"light", Strategy::Light},
                                                    {"light+bsdf", Strategy::LightBsdf},
                                                    {"mis", Strategy::Mis}};
  for (const auto& [name, strategy] : names) {
    const Scene s = parse(scene_text("{}", "[]", std::string(R"("render": {"strategy": ")") + name + "\"}"));
    EXPECT_EQ(s.render.strategy, strategy) << name;
  }
}

// ------------------------------------------------------------ materials

TEST(SceneLoader, MaterialsOfEachTypeAndTheirDefaults) {
  const Scene s = parse(scene_text(R"({
    "plain": {"type": "diffuse"},
    "grey": {"type": "diffuse", "albedo": 0.25},
    "glow": {"type": "diffuse", "albedo": [0.1, 0.2, 0.3], "emission": [1, 2, 3], "two_sided": true},
    "mirror": {"type": "mirror"},
    "tinted": {"type": "mirror", "reflectance": [0.9, 0.8, 0.7]},
    "lamp": {"type": "emissive", "radiance": 7},
    "front": {"type": "disney", "one_sided": true}
  })", "[]"));
  ASSERT_EQ(s.materials.size(), 7u);
  const auto get = [&s](const std::string& name) -> const Material& {
    const auto it = std::find_if(s.materials.begin(), s.materials.end(),
                                 [&](const Material& m) { return m.name == name; });
    EXPECT_NE(it, s.materials.end()) << name;
    return *it;
  };
  EXPECT_EQ(get("plain").type, MaterialType::Diffuse);
  expect_vec(get("plain").albedo, vec3(0.5f));
  expect_vec(get("plain").emission, vec3(0.0f));
  EXPECT_FALSE(get("plain").two_sided_emission);
  EXPECT_FALSE(get("plain").emits());
  expect_vec(get("grey").albedo, vec3(0.25f));
  expect_vec(get("glow").albedo, vec3(0.1f, 0.2f, 0.3f));
  expect_vec(get("glow").emission, vec3(1, 2, 3));
  EXPECT_TRUE(get("glow").two_sided_emission);
  EXPECT_TRUE(get("glow").emits());
  EXPECT_EQ(get("mirror").type, MaterialType::Mirror);
  expect_vec(get("mirror").albedo, vec3(1.0f));
  EXPECT_TRUE(get("mirror").is_pure_impulse());
  expect_vec(get("tinted").albedo, vec3(0.9f, 0.8f, 0.7f));
  EXPECT_EQ(get("lamp").type, MaterialType::Emissive);
  expect_vec(get("lamp").emission, vec3(7.0f));
  expect_vec(get("lamp").albedo, vec3(0.0f));
  EXPECT_FALSE(get("lamp").scatters());
  EXPECT_FALSE(get("lamp").two_sided_emission);
  EXPECT_FALSE(get("plain").one_sided);  // two-sided by default
  EXPECT_TRUE(get("front").one_sided);
  // Emitting materials that no shape uses light nothing.
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("no light"), std::string::npos) << s.warnings[0];
}

TEST(SceneLoader, ShapesReferToTheirMaterialByName) {
  const Scene s = parse(scene_text(kMaterials, R"([{"type": "sphere", "material": "lamp"},
                                                   {"type": "box", "material": "white"}])"));
  ASSERT_EQ(s.shapes.size(), 2u);
  EXPECT_EQ(s.materials[s.shapes[0].material].name, "lamp");
  EXPECT_EQ(s.materials[s.shapes[1].material].name, "white");
}

// ------------------------------------------------------------ shapes

TEST(SceneLoader, SphereDefaultsAndExplicitValues) {
  const Shape unit = only_shape(R"({"type": "sphere", "material": "white"})");
  EXPECT_EQ(unit.kind, Shape::Kind::Sphere);
  expect_vec(unit.center, vec3(0.0f));
  EXPECT_FLOAT_EQ(unit.radius, 1.0f);
  EXPECT_FALSE(unit.flip_normals);
  EXPECT_EQ(unit.description, "shapes[0] (sphere)");

  const Shape s = only_shape(R"({"type": "sphere", "material": "white", "center": [1, 2, 3], "radius": 0.5,
                                 "flip_normals": true})");
  expect_vec(s.center, vec3(1, 2, 3));
  EXPECT_FLOAT_EQ(s.radius, 0.5f);
  EXPECT_TRUE(s.flip_normals);
}

TEST(SceneLoader, RectangleIsTheUnitSquareFacingPlusZ) {
  const Shape r = only_shape(R"({"type": "rectangle", "material": "white"})");
  EXPECT_EQ(r.kind, Shape::Kind::Triangles);
  ASSERT_EQ(r.mesh.positions.size(), 4u);
  ASSERT_EQ(r.mesh.triangles.size(), 2u);
  expect_vec(r.mesh.positions[0], vec3(-1, -1, 0));
  expect_vec(r.mesh.positions[2], vec3(1, 1, 0));
  for (std::size_t t = 0; t < 2; ++t) expect_vec(geometric_normal(r.mesh, t), vec3(0, 0, 1));
}

TEST(SceneLoader, BoxIsTheUnitCubeWithOutwardFaces) {
  const Shape b = only_shape(R"({"type": "box", "material": "white"})");
  ASSERT_EQ(b.mesh.triangles.size(), 12u);
  for (const vec3& p : b.mesh.positions) EXPECT_NEAR(std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}), 1.0f, kTol);
  for (std::size_t t = 0; t < 12; ++t) {
    const vec3 n = geometric_normal(b.mesh, t), c = centroid(b.mesh, t);
    EXPECT_NEAR(glm::dot(n, c), 1.0f, kTol) << "triangle " << t;  // each face lies at distance 1 along its normal
  }
}

// ------------------------------------------------------------ transforms

TEST(SceneLoader, TranslateMovesEveryVertex) {
  const Shape r = only_shape(R"({"type": "rectangle", "material": "white", "transform": {"translate": [1, 2, 3]}})");
  expect_vec(r.mesh.positions[0], vec3(0, 1, 3));
  expect_vec(r.mesh.positions[2], vec3(2, 3, 3));
}

TEST(SceneLoader, ScaleByNumberOrVector) {
  const Shape uniform = only_shape(R"({"type": "rectangle", "material": "white", "transform": {"scale": 2.5}})");
  expect_vec(uniform.mesh.positions[2], vec3(2.5f, 2.5f, 0));
  const Shape vector = only_shape(R"({"type": "box", "material": "white", "transform": {"scale": [1, 2, 3]}})");
  for (const vec3& p : vector.mesh.positions) {
    EXPECT_NEAR(std::abs(p.x), 1.0f, kTol);
    EXPECT_NEAR(std::abs(p.y), 2.0f, kTol);
    EXPECT_NEAR(std::abs(p.z), 3.0f, kTol);
  }
}

TEST(SceneLoader, RotateIsCounterClockwiseInDegreesAboutTheAxis) {
  // +90 degrees about +z takes +x to +y; the axis need not be normalized.
  const Shape r = only_shape(
      R"({"type": "rectangle", "material": "white", "transform": {"rotate": {"axis": [0, 0, 5], "angle": 90}}})");
  expect_vec(r.mesh.positions[1], vec3(1, 1, 0));   // (1, -1, 0) -> (1, 1, 0)
  expect_vec(r.mesh.positions[2], vec3(-1, 1, 0));  // (1, 1, 0) -> (-1, 1, 0)
  // -90 about +x tips the +z normal to +y (as the Cornell box floor does).
  const Shape floor = only_shape(
      R"({"type": "rectangle", "material": "white", "transform": {"rotate": {"axis": [1, 0, 0], "angle": -90}}})");
  expect_vec(geometric_normal(floor.mesh, 0), vec3(0, 1, 0));
}

TEST(SceneLoader, MatrixIsGivenRowByRow) {
  const Shape r = only_shape(R"({"type": "rectangle", "material": "white", "transform": {"matrix": [
      0, -1, 0, 10,
      1,  0, 0, 20,
      0,  0, 2, 30,
      0,  0, 0, 1]}})");
  // (1, -1, 0) -> (1, 1, 0) + (10, 20, 30).
  expect_vec(r.mesh.positions[1], vec3(11, 21, 30));
  expect_vec(r.mesh.positions[3], vec3(9, 19, 30));  // (-1, 1, 0) -> (-1, -1, 0) + t
}

TEST(SceneLoader, TransformListAppliesTheFirstStepFirst) {
  const Shape r = only_shape(R"({"type": "rectangle", "material": "white", "transform": [
      {"scale": 2},
      {"rotate": {"axis": [0, 0, 1], "angle": 90}},
      {"translate": [1, 0, 0]}]})");
  // (1, -1, 0): scale -> (2, -2, 0), rotate -> (2, 2, 0), translate -> (3, 2, 0).
  expect_vec(r.mesh.positions[1], vec3(3, 2, 0));
  // (-1, -1, 0) -> (-2, -2, 0) -> (2, -2, 0) -> (3, -2, 0).
  expect_vec(r.mesh.positions[0], vec3(3, -2, 0));
  // Nested lists are flattened in order.
  const Shape nested = only_shape(R"({"type": "rectangle", "material": "white", "transform": [
      [{"scale": 2}, {"rotate": {"axis": [0, 0, 1], "angle": 90}}], {"translate": [1, 0, 0]}]})");
  expect_vec(nested.mesh.positions[1], vec3(3, 2, 0));
}

// The front side is where the transformed normal points: for a mirroring
// transform the loader must reverse the winding to keep it.
TEST(SceneLoader, MirroringTransformKeepsTheFrontSide) {
  struct Case {
    const char* shape;
    mat4 xf;
  };
  const Case cases[] = {
      {R"({"type": "rectangle", "material": "white", "transform": {"scale": [-1, 1, 1]}})",
       glm::scale(mat4(1.0f), vec3(-1, 1, 1))},
      {R"({"type": "rectangle", "material": "white", "transform": {"scale": [1, 1, -2]}})",
       glm::scale(mat4(1.0f), vec3(1, 1, -2))},
      {R"({"type": "rectangle", "material": "white", "transform": [{"scale": -1}, {"translate": [0, 0, 1]}]})",
       glm::translate(mat4(1.0f), vec3(0, 0, 1)) * glm::scale(mat4(1.0f), vec3(-1.0f))},
      {R"({"type": "rectangle", "material": "white", "transform": {"matrix": [0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}})",
       mat4(vec4(0, 1, 0, 0), vec4(1, 0, 0, 0), vec4(0, 0, 1, 0), vec4(0, 0, 0, 1))},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.shape);
    const Shape r = only_shape(c.shape);
    ASSERT_EQ(r.mesh.triangles.size(), 2u);
    const vec3 expected = glm::normalize(glm::transpose(glm::inverse(mat3(c.xf))) * vec3(0, 0, 1));
    for (std::size_t t = 0; t < 2; ++t) expect_vec(geometric_normal(r.mesh, t), expected);
  }
  // A mirrored box still faces outward.
  const Shape box = only_shape(R"({"type": "box", "material": "white", "transform": {"scale": [-1, 2, 1]}})");
  for (std::size_t t = 0; t < box.mesh.triangles.size(); ++t)
    EXPECT_GT(glm::dot(geometric_normal(box.mesh, t), centroid(box.mesh, t)), 0.0f) << "triangle " << t;
}

TEST(SceneLoader, SphereTakesARigidUniformlyScaledTransform) {
  const Shape s = only_shape(R"({"type": "sphere", "material": "white", "center": [1, 0, 0], "radius": 0.5,
      "transform": [{"scale": 2}, {"rotate": {"axis": [0, 0, 1], "angle": 90}}, {"translate": [0, 0, 3]}]})");
  expect_vec(s.center, vec3(0, 2, 3));
  EXPECT_NEAR(s.radius, 1.0f, kTol);
  // A uniform mirror keeps a sphere a sphere with a positive radius.
  const Shape m = only_shape(R"({"type": "sphere", "material": "white", "transform": {"scale": -3}})");
  EXPECT_NEAR(m.radius, 3.0f, kTol);
}

TEST(SceneLoader, SphereRejectsANonUniformScale) {
  const std::string text =
      scene_text(kMaterials, R"([{"type": "sphere", "material": "white", "transform": {"scale": [1, 2, 1]}}])");
  expect_error(text, where_in(text, "\"transform\""), "/shapes/0/transform",
               "a sphere's transform may only rotate, translate and scale uniformly");
  const std::string shear = scene_text(
      kMaterials,
      R"([{"type": "sphere", "material": "white", "transform": {"matrix": [1, 0.5, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}}])");
  EXPECT_NE(error_of(shear).find("scale uniformly"), std::string::npos) << error_of(shear);
}

TEST(SceneLoader, TransformThatCollapsesSomeTrianglesWarns) {
  // One triangle 1e-10 across, one 1 across; scaled by 1e-20 the small one's
  // area underflows to zero and is dropped, the large one remains.
  const test::ScopedTempDir folder("scene-loader-collapse");
  const fs::path& dir = folder.path();
  std::ofstream(dir / "two.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1e-10 0 0\nv 0 1e-10 0\nf 1 2 3\nf 1 4 5\n";
  const Scene s = parse(scene_text(kMaterials, R"([{"type": "mesh", "file": "two.obj", "material": "lamp",
                                                     "transform": {"scale": 1e-20}}])"),
                        dir / "scene.json");
  ASSERT_EQ(s.shapes.size(), 1u);
  EXPECT_EQ(s.shapes[0].mesh.triangles.size(), 1u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("shapes[0] (mesh two.obj): the transform made 1 triangle(s) degenerate"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("scene.json:"), std::string::npos) << s.warnings[0];
}

// ------------------------------------------------------------ lights

TEST(SceneLoader, PointAndEnvironmentLights) {
  const Scene s = parse(scene_text("{}", "[]", R"("lights": [
    {"type": "point", "position": [1, 2, 3], "intensity": [4, 5, 6]},
    {"type": "point", "position": [0, 0, 0], "intensity": 2},
    {"type": "environment", "radiance": 0.5}])"));
  ASSERT_EQ(s.delta_lights.size(), 2u);
  expect_vec(s.delta_lights[0].position, vec3(1, 2, 3));
  expect_vec(s.delta_lights[0].intensity, vec3(4, 5, 6));
  expect_vec(s.delta_lights[1].intensity, vec3(2.0f));
  ASSERT_TRUE(s.environment.has_value());
  expect_vec(*s.environment, vec3(0.5f));
  EXPECT_TRUE(s.warnings.empty());
}

TEST(SceneLoader, SpotAndDirectionalLights) {
  const Scene s = parse(scene_text("{}", "[]", R"("lights": [
    {"type": "spot", "position": [1, 2, 3], "look_at": [1, 2, 0], "intensity": [4, 5, 6], "cone_angle": 60, "falloff_start": 30},
    {"type": "spot", "position": [0, 0, 0], "direction": [0, 2, 0], "intensity": 2, "cone_angle": 90},
    {"type": "directional", "direction": [0, 0, -3], "irradiance": [1, 2, 3]}])"));
  ASSERT_EQ(s.delta_lights.size(), 3u);
  EXPECT_EQ(s.delta_lights[0].kind, DeltaLight::Kind::Spot);
  expect_vec(s.delta_lights[0].position, vec3(1, 2, 3));
  expect_vec(s.delta_lights[0].direction, vec3(0, 0, -1));
  expect_vec(s.delta_lights[0].intensity, vec3(4, 5, 6));
  EXPECT_NEAR(s.delta_lights[0].cos_outer, 0.5f, 1e-6f);
  EXPECT_NEAR(s.delta_lights[0].cos_inner, std::sqrt(0.75f), 1e-6f);
  // Without falloff_start the edge is hard (inner = outer).
  expect_vec(s.delta_lights[1].direction, vec3(0, 1, 0));
  EXPECT_NEAR(s.delta_lights[1].cos_outer, 0.0f, 1e-6f);
  EXPECT_EQ(s.delta_lights[1].cos_inner, s.delta_lights[1].cos_outer);
  EXPECT_EQ(s.delta_lights[2].kind, DeltaLight::Kind::Directional);
  expect_vec(s.delta_lights[2].direction, vec3(0, 0, -1));
  expect_vec(s.delta_lights[2].intensity, vec3(1, 2, 3));
  EXPECT_TRUE(s.warnings.empty());
}

TEST(SceneLoader, BlackLightsDoNotCountAsLight) {
  for (const char* lights : {R"("lights": [{"type": "point", "position": [0, 0, 0], "intensity": 0}])",
                             R"("lights": [{"type": "environment", "radiance": [0, 0, 0]}])"}) {
    const Scene s = parse(scene_text(R"({"m": {"type": "emissive", "radiance": 0}})",
                                     R"([{"type": "sphere", "material": "m"}])", lights));
    ASSERT_EQ(s.warnings.size(), 1u) << lights;
    EXPECT_NE(s.warnings[0].find("no light"), std::string::npos) << s.warnings[0];
  }
}

// ------------------------------------------------------------ files

class SceneLoaderFiles : public test::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    fs::create_directories(dir_ / "scenes" / "meshes");
  }
  fs::path write(const fs::path& relative, const std::string& text) const {
    std::ofstream out(dir_ / relative, std::ios::binary);
    out << text;
    EXPECT_TRUE(out.good()) << relative;
    return dir_ / relative;
  }
};

// A unit square in z = 0 as one OBJ quad, counter-clockwise seen from +z.
const char* const kQuadObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

const char* const kTrianglePly =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n2 0 0\n0 2 0\n3 0 1 2\n";

TEST_F(SceneLoaderFiles, MeshPathsAreRelativeToTheSceneFolder) {
  write("scenes/meshes/quad.obj", kQuadObj);
  const std::string text = scene_text(kMaterials, R"([{"type": "mesh", "file": "meshes/quad.obj", "material": "lamp",
      "transform": [{"scale": [2, 3, 1]}, {"translate": [0, 0, -1]}]}])");
  const fs::path scene_file = write("scenes/scene.json", text);

  // Whatever the working directory, the mesh is found beside the scene.
  const Scene loaded = load_scene(scene_file);
  ASSERT_EQ(loaded.shapes.size(), 1u);
  const Shape& quad = loaded.shapes[0];
  EXPECT_EQ(quad.kind, Shape::Kind::Triangles);
  EXPECT_EQ(quad.description, "shapes[0] (mesh meshes/quad.obj)");
  ASSERT_EQ(quad.mesh.triangles.size(), 2u);
  expect_vec(quad.mesh.positions[2], vec3(2, 3, -1));
  expect_vec(geometric_normal(quad.mesh, 0), vec3(0, 0, 1));
  EXPECT_TRUE(loaded.warnings.empty());
  EXPECT_EQ(loaded.name, "scene");

  // parse_scene anchors the same way on a file that need not exist.
  const Scene parsed = parse_scene(text, dir_ / "scenes" / "not-written.json");
  EXPECT_EQ(parsed.shapes[0].mesh.triangles.size(), 2u);
  // ... and from another folder the relative path no longer resolves.
  const std::string message = error_of(text, dir_ / "elsewhere.json");
  EXPECT_NE(message.find("meshes/quad.obj"), std::string::npos) << message;
}

TEST_F(SceneLoaderFiles, PlyMeshWithMirroringTransform) {
  write("scenes/tri.ply", kTrianglePly);
  const Scene s = load_scene(write("scenes/scene.json", scene_text(kMaterials,
      R"([{"type": "mesh", "file": "tri.ply", "material": "white", "transform": {"scale": [1, -1, 1]}},
          {"type": "sphere", "material": "lamp"}])")));
  const Shape& tri = s.shapes[0];
  ASSERT_EQ(tri.mesh.triangles.size(), 1u);
  expect_vec(tri.mesh.positions[2], vec3(0, -2, 0));
  expect_vec(geometric_normal(tri.mesh, 0), vec3(0, 0, 1));  // n' = M^-T n = (0, 0, 1)
}

TEST_F(SceneLoaderFiles, AbsoluteMeshPathIsUsedAsIs) {
  const fs::path mesh = write("scenes/meshes/quad.obj", kQuadObj);
  const Scene s = parse_scene(scene_text(kMaterials, R"([{"type": "mesh", "file": ")" + mesh.string() +
                                                         R"(", "material": "lamp"}])"),
                              "/nonexistent/scene.json");
  EXPECT_EQ(s.shapes[0].mesh.triangles.size(), 2u);
}

TEST_F(SceneLoaderFiles, DegenerateMeshTrianglesAreDroppedCountedAndWarned) {
  write("scenes/degenerate.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 1 1 3\n");  // the last two are degenerate
  const std::string text = scene_text(kMaterials, R"([{"type": "mesh", "file": "degenerate.obj", "material": "lamp"}])");
  const Scene s = load_scene(write("scenes/scene.json", text));
  EXPECT_EQ(s.shapes[0].mesh.triangles.size(), 1u);
  ASSERT_EQ(s.warnings.size(), 1u);
  const std::string& w = s.warnings[0];
  EXPECT_NE(w.find("scene.json:" + where_in(text, "\"file\"") + ": /shapes/0/file: "), std::string::npos) << w;
  EXPECT_NE(w.find("degenerate.obj: dropped 2 degenerate triangle(s) of 3"), std::string::npos) << w;
}

TEST_F(SceneLoaderFiles, MeshErrorsNameSceneAndMesh) {
  write("scenes/nan.ply", std::string(kTrianglePly).replace(std::string(kTrianglePly).find("2 0 0\n"), 6, "nan 0 0\n"));
  const std::string text = scene_text(kMaterials, R"([{"type": "mesh", "file": "nan.ply", "material": "lamp"}])");
  const std::string message = error_of(text, dir_ / "scenes" / "scene.json");
  EXPECT_EQ(message.rfind((dir_ / "scenes" / "scene.json").string() + ":" + where_in(text, "\"file\"") +
                              ": /shapes/0/file: ",
                          0),
            0u)
      << message;
  EXPECT_NE(message.find("nan.ply: vertex 1 has a non-finite coordinate"), std::string::npos) << message;

  const std::string empty = scene_text(kMaterials, R"([{"type": "mesh", "file": "", "material": "lamp"}])");
  EXPECT_NE(error_of(empty).find("/shapes/0/file: the mesh file name is empty"), std::string::npos) << error_of(empty);
}

// ------------------------------------------------------------ built-in

TEST(SceneLoader, BuiltinCornellBoxLoads) {
  const Scene s = builtin_cornell_box();
  EXPECT_EQ(s.name, "cornell");
  EXPECT_TRUE(s.file.empty());
  ASSERT_EQ(s.shapes.size(), 8u);
  int emitters = 0;
  for (const Shape& shape : s.shapes) {
    EXPECT_EQ(shape.kind, Shape::Kind::Triangles);
    emitters += s.materials[shape.material].emits() ? 1 : 0;
  }
  EXPECT_EQ(emitters, 1);
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.film.width, 512);
  EXPECT_EQ(s.render.spp, 64);
  // The ceiling light faces down, into the box.
  const Shape& light = s.shapes[7];
  expect_vec(geometric_normal(light.mesh, 0), vec3(0, -1, 0));
  EXPECT_NEAR(light.mesh.positions[0].y, 0.998f, kTol);
  // The compiled-in text is the file in scenes/.
  const Scene from_file = load_scene(fs::path(PATHLAB_SOURCE_DIR) / "scenes" / "cornell-box.json");
  EXPECT_EQ(from_file.shapes.size(), 8u);
  EXPECT_EQ(from_file.name, "cornell-box");
}

// ------------------------------------------------------------ errors

TEST(SceneLoaderErrors, ErrorInANestedValueReportsItsPosition) {
  const std::string text = scene_text(kMaterials, R"([
    {"type": "sphere", "material": "lamp"},
    {"type": "rectangle", "material": "white",
     "transform": [{"translate": [0, 1, 0]}, {"rotate": {"axis": [0, 1, 0], "angle": "90"}}]}
  ])");
  // Line 8 is the transform; the key "angle" starts at column 77.
  EXPECT_EQ(where_in(text, "\"angle\""), "8:77");
  expect_error(text, "8:77", "/shapes/1/transform/1/rotate/angle", "expected a number, found the string \"90\"");

  // An array element is placed where its value starts.
  const std::string element = scene_text(kMaterials, R"([{"type": "sphere", "material": "lamp",
      "center": [0, 0,
                 true]}])");
  expect_error(element, where_in(element, "true"), "/shapes/0/center/2", "expected a number, found true");
}

TEST(SceneLoaderErrors, UnknownKeysSuggestTheNearestValidOne) {
  const std::string text = scene_text(R"({"m": {"type": "diffuse", "albedoo": 0.5}})", "[]");
  expect_error(text, where_in(text, "\"albedoo\""), "/materials/m/albedoo", "unknown key 'albedoo' (did you mean 'albedo'?)");
  const std::string top = R"({"pathlab_scene": 1, "camra": {}})";
  EXPECT_NE(error_of(top).find("/camra: unknown key 'camra' (did you mean 'camera'?)"), std::string::npos)
      << error_of(top);
  const std::string far = scene_text("{}", "[]", R"("render": {"photons": 4})");
  const std::string message = error_of(far);
  EXPECT_NE(message.find("/render/photons: unknown key 'photons'"), std::string::npos) << message;
  EXPECT_EQ(message.find("did you mean"), std::string::npos) << message;
  // Another material type's key gets a pointed message.
  const std::string mirror = scene_text(R"({"m": {"type": "mirror", "albedo": 0.5}})", "[]");
  EXPECT_NE(error_of(mirror).find("a mirror material has no 'albedo'; its colour is 'reflectance'"), std::string::npos)
      << error_of(mirror);
  const std::string emissive = scene_text(R"({"m": {"type": "emissive", "emission": 1}})", "[]");
  EXPECT_NE(error_of(emissive).find("an emissive material has no 'emission'; its emitted light is 'radiance'"),
            std::string::npos)
      << error_of(emissive);
  // "one_sided" is for reflecting materials only.
  const std::string glass = scene_text(R"({"m": {"type": "dielectric", "one_sided": true}})", "[]");
  EXPECT_NE(error_of(glass).find("a dielectric material has no 'one_sided'; glass has an inside"), std::string::npos)
      << error_of(glass);
  const std::string lamp = scene_text(R"({"m": {"type": "emissive", "radiance": 1, "one_sided": true}})", "[]");
  EXPECT_NE(error_of(lamp).find("an emissive material has no 'one_sided'"), std::string::npos) << error_of(lamp);
}

TEST(SceneLoaderErrors, UnknownNamesSuggestTheNearest) {
  const std::string type = scene_text(R"({"m": {"type": "difuse"}})", "[]");
  expect_error(type, where_in(type, "\"type\""), "/materials/m/type", "unknown material type 'difuse' (did you mean 'diffuse'?)");
  const std::string other = scene_text(R"({"m": {"type": "glass"}})", "[]");
  EXPECT_NE(error_of(other).find("expected diffuse, mirror, emissive, disney or dielectric"), std::string::npos) << error_of(other);
  const std::string ref = scene_text(kMaterials, R"([{"type": "sphere", "material": "whit"}])");
  expect_error(ref, where_in(ref, "\"material\""), "/shapes/0/material", "no material named 'whit' (did you mean 'white'?)");
  const std::string shape = scene_text(kMaterials, R"([{"type": "spere", "material": "white"}])");
  EXPECT_NE(error_of(shape).find("unknown shape type 'spere' (did you mean 'sphere'?)"), std::string::npos);
  const std::string step = scene_text(kMaterials, R"([{"type": "box", "material": "white", "transform": {"translat": [0, 0, 0]}}])");
  EXPECT_NE(error_of(step).find("unknown transform step 'translat' (did you mean 'translate'?)"), std::string::npos);
  const std::string light = scene_text("{}", "[]", R"("lights": [{"type": "pont"}])");
  EXPECT_NE(error_of(light).find("unknown light type 'pont' (did you mean 'point'?)"), std::string::npos)
      << error_of(light);
  const std::string filter = scene_text("{}", "[]", R"("film": {"filter": "gauss"})");
  EXPECT_NE(error_of(filter).find("unknown filter 'gauss' (expected box or bilinear)"), std::string::npos);
  const std::string strategy = scene_text("{}", "[]", R"("render": {"strategy": "path"})");
  EXPECT_NE(error_of(strategy).find("unknown strategy 'path' (expected cosine, bsdf, light, light+bsdf or mis)"),
            std::string::npos)
      << error_of(strategy);
  const std::string light_bsdf = scene_text("{}", "[]", R"("render": {"strategy": "light-bsdf"})");
  EXPECT_NE(error_of(light_bsdf).find("(did you mean 'light+bsdf'?)"), std::string::npos) << error_of(light_bsdf);
}

TEST(SceneLoaderErrors, VersionAndStructure) {
  EXPECT_NE(error_of(R"({"camera": {}})").find("scene.json:1:1: (top level): missing 'pathlab_scene'"), std::string::npos)
      << error_of(R"({"camera": {}})");
  // The version is checked before the keys: a newer file may have new ones.
  const std::string v2 = R"({"pathlab_scene": 2, "textures": {}})";
  EXPECT_EQ(error_of(v2), "scene.json:1:2: /pathlab_scene: unsupported scene format version 2 (this pathlab reads version 1)");
  EXPECT_NE(error_of(R"({"pathlab_scene": "1"})").find("expected an integer, found the string \"1\""), std::string::npos);
  EXPECT_NE(error_of("[1, 2]").find("scene.json:1:1: (top level): expected an object, found an array of 2"),
            std::string::npos)
      << error_of("[1, 2]");
  EXPECT_NE(error_of(R"({"pathlab_scene": 1, "camera": {"position": [0, 0, 1]}})").find(
                "/camera: missing required key 'look_at'"),
            std::string::npos);
  // A misspelt required key is pointed out.
  const std::string misspelt = scene_text(R"({"m": {"typ": "diffuse"}})", "[]");
  EXPECT_NE(error_of(misspelt).find("missing required key 'type' (is 'typ' a misspelling of it?)"), std::string::npos)
      << error_of(misspelt);
  EXPECT_NE(error_of(scene_text("{}", "{}")).find("/shapes: expected an array of shapes"), std::string::npos);
  // Malformed JSON names file, line and column.
  EXPECT_EQ(error_of("{\n  \"pathlab_scene\": 1,\n  \"camera\": {\"position\": [0, 0] \"look_at\": 1}\n}").rfind(
                "scene.json:3:", 0),
            0u);
}

TEST(SceneLoaderErrors, OverflowingNumberIsMalformedJson) {
  // 1e999 is the only way to write an infinity; nlohmann rejects it with an
  // out_of_range exception that must not escape as anything but InputError.
  const std::string text = scene_text(R"({"m": {"type": "diffuse",
    "emission": [1, 1e999, 1]}})", "[]");
  EXPECT_EQ(error_of(text), "scene.json:5:21: malformed JSON: number '1e999' is out of range (numbers must be finite)");
  EXPECT_EQ(where_in(text, "1e999"), "5:21");
  // A larger literal that contains it is not mistaken for it.
  const std::string negative = scene_text("{}", "[]", R"("render": {"spp": 11e999, "seed": -1e999})");
  EXPECT_NE(error_of(negative).find("number '11e999'"), std::string::npos) << error_of(negative);
  EXPECT_NE(error_of(negative).find("scene.json:" + where_in(negative, "11e999") + ":"), std::string::npos)
      << error_of(negative);
}

TEST(SceneLoaderErrors, WrongTypes) {
  const std::string fov = scene_text("{}", "[]", "\"render\": {\"spp\": 1.5}");
  EXPECT_NE(error_of(fov).find("/render/spp: expected an integer, found the number 1.5"), std::string::npos) << error_of(fov);
  const std::string color = scene_text(R"({"m": {"type": "diffuse", "albedo": "0.5"}})", "[]");
  EXPECT_NE(error_of(color).find("expected a colour: one number or an array of 3 numbers, found the string \"0.5\""),
            std::string::npos)
      << error_of(color);
  const std::string vec = scene_text(kMaterials, R"([{"type": "sphere", "material": "white", "center": [1, 2]}])");
  EXPECT_NE(error_of(vec).find("expected an array of 3 numbers, found an array of 2"), std::string::npos) << error_of(vec);
  const std::string flag = scene_text(kMaterials, R"([{"type": "sphere", "material": "white", "flip_normals": 1}])");
  EXPECT_NE(error_of(flag).find("expected true or false, found the number 1"), std::string::npos) << error_of(flag);
  const std::string name = scene_text(kMaterials, R"([{"type": "sphere", "material": null}])");
  EXPECT_NE(error_of(name).find("expected a string, found null"), std::string::npos) << error_of(name);
  const std::string xf = scene_text(kMaterials, R"([{"type": "box", "material": "white", "transform": 2}])");
  EXPECT_NE(error_of(xf).find("/shapes/0/transform: expected a transform step"), std::string::npos) << error_of(xf);
}

TEST(SceneLoaderErrors, OutOfRangeValues) {
  struct Case {
    std::string text, message;
  };
  const std::string m = R"({"m": {"type": "diffuse"}})";
  const Case cases[] = {
      {scene_text(R"({"m": {"type": "diffuse", "albedo": [0.5, 1.2, 0.5]}})", "[]"),
       "/materials/m/albedo: components must lie in [0, 1]"},
      {scene_text(R"({"m": {"type": "mirror", "reflectance": -0.1}})", "[]"),
       "/materials/m/reflectance: components must not be negative"},
      {scene_text(R"({"m": {"type": "diffuse", "emission": [1, -1, 1]}})", "[]"),
       "/materials/m/emission: components must not be negative"},
      {scene_text(R"({"m": {"type": "emissive", "radiance": 1e39}})", "[]"),
       "/materials/m/radiance: number 1e+39 is too large"},
      {scene_text(m, "[]", R"("film": {"resolution": [0, 10]})"), "/film/resolution: width and height must lie in"},
      {scene_text(m, "[]", R"("film": {"resolution": [10]})"), "/film/resolution: expected [width, height]"},
      {scene_text(m, "[]", R"("render": {"spp": 0})"), "/render/spp: spp must lie in [1, 16777216]"},
      {scene_text(m, "[]", R"("render": {"max_depth": -2})"), "/render/max_depth: max_depth must be -1"},
      {scene_text(m, "[]", R"("render": {"seed": -1})"), "/render/seed: seed must not be negative"},
      {scene_text(m, "[]", R"("render": {"spp": 99999999999999999999})"), "/render/spp: expected an integer"},
      {scene_text(m, R"([{"type": "sphere", "material": "m", "radius": -1}])"), "/shapes/0/radius: radius must be positive"},
      {scene_text(m, R"([{"type": "box", "material": "m", "transform": {"scale": [1, 0, 1]}}])"),
       "/shapes/0/transform/scale: scale must not be zero"},
      {scene_text(m, R"([{"type": "box", "material": "m", "transform": {"rotate": {"axis": [0, 0, 0], "angle": 1}}}])"),
       "/shapes/0/transform/rotate/axis: axis must not be zero"},
      {scene_text(m, R"([{"type": "box", "material": "m", "transform": {"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1]}}])"),
       "/shapes/0/transform/matrix: the last row must be [0, 0, 0, 1]"},
      {scene_text(m, R"([{"type": "box", "material": "m", "transform": {"matrix": [1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}}])"),
       "/shapes/0/transform/matrix: matrix is singular"},
      {scene_text(m, R"([{"type": "box", "material": "m", "transform": {"matrix": [1, 0, 0]}}])"),
       "/shapes/0/transform/matrix: expected 16 numbers, row by row"},
      {scene_text(m, R"([{"type": "box", "material": "m", "transform": {"scale": 2, "translate": [0, 0, 0]}}])"),
       "/shapes/0/transform: a transform step has exactly one of"},
      {scene_text(m, "[]", R"("lights": [{"type": "environment", "radiance": 1}, {"type": "environment", "radiance": 1}])"),
       "/lights/1: only one environment light is allowed"},
  };
  for (const Case& c : cases) {
    const std::string message = error_of(c.text);
    EXPECT_NE(message.find(c.message), std::string::npos) << message << "\nexpected: " << c.message;
  }
}

TEST(SceneLoaderErrors, CameraProblems) {
  const auto camera = [](const std::string& body) {
    return error_of(R"({"pathlab_scene": 1, "camera": )" + body + R"(, "materials": {}, "shapes": []})");
  };
  EXPECT_NE(camera(R"({"position": [1, 1, 1], "look_at": [1, 1, 1]})").find("/camera/look_at: look_at must differ from position"),
            std::string::npos);
  EXPECT_NE(camera(R"({"position": [0, 0, 0], "look_at": [0, 0, 1], "up": [0, 0, 2]})").find(
                "/camera/up: up must not be zero or parallel to the viewing direction"),
            std::string::npos);
  // Looking straight down with the default up: the message must say where
  // the problem is although "up" is not in the file.
  const std::string down = camera(R"({"position": [0, 5, 0], "look_at": [0, 0, 0]})");
  EXPECT_EQ(down.rfind("scene.json:1:22: /camera: ", 0), 0u) << down;
  EXPECT_NE(down.find("default up [0, 1, 0] is parallel"), std::string::npos) << down;
  EXPECT_NE(camera(R"({"position": [0, 0, 1], "look_at": [0, 0, 0], "fov_y": 180})").find("/camera/fov_y: fov_y 180 is outside (0, 179] degrees"),
            std::string::npos);
  EXPECT_NE(camera(R"({"position": [0, 0, 1], "look_at": [0, 0, 0], "aperture_radius": -1})").find("must not be negative"),
            std::string::npos);
  EXPECT_NE(camera(R"({"position": [0, 0, 1], "look_at": [0, 0, 0], "focus_distance": 0})").find("focus_distance must be positive"),
            std::string::npos);
  EXPECT_NE(camera(R"({"position": [3e38, 0, 0], "look_at": [-3e38, 0, 0]})").find("beyond the scene coordinate limit"), std::string::npos);
}

TEST(SceneLoaderErrors, ZeroAreaLights) {
  // A rectangle light scaled below float resolution.
  const std::string rect = scene_text(kMaterials, R"([{"type": "rectangle", "material": "lamp", "transform": {"scale": 1e-30}}])");
  expect_error(rect, where_in(rect, "\"transform\""), "/shapes/0/transform", "zero-area light");
  // Not a light: same problem, no "light" in the message.
  const std::string plain = scene_text(kMaterials, R"([{"type": "rectangle", "material": "white", "transform": {"scale": 1e-30}}])");
  EXPECT_NE(error_of(plain).find("the shape has no area left after its transform"), std::string::npos);
  EXPECT_EQ(error_of(plain).find("light"), std::string::npos) << error_of(plain);
  // A sphere light whose radius underflows under its transform.
  const std::string sphere = scene_text(
      kMaterials, R"([{"type": "sphere", "material": "lamp", "radius": 1e-10, "transform": [{"scale": 1e-30}, {"scale": 1e-30}]}])");
  expect_error(sphere, where_in(sphere, "\"transform\""), "/shapes/0/transform", "zero-area light: the sphere's radius is zero");
  // A sphere light of radius 0.
  const std::string zero = scene_text(kMaterials, R"([{"type": "sphere", "material": "lamp", "radius": 0}])");
  expect_error(zero, where_in(zero, "\"radius\""), "/shapes/0/radius", "radius must be positive");
  // Vertices pushed to infinity are not reported as a zero area.
  const std::string far = scene_text(kMaterials, R"([{"type": "rectangle", "material": "lamp", "transform": [{"scale": 3e38}, {"scale": 10}]}])");
  EXPECT_NE(error_of(far).find("/shapes/0/transform: the transform moves vertices beyond the scene coordinate limit 1e16"), std::string::npos)
      << error_of(far);
}

}  // namespace
}  // namespace pathlab
