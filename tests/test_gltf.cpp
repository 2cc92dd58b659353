// glTF 2.0 files written by the tests: containers (embedded, .glb, external
// .bin), index types, strides, modes, the node hierarchy and what it does to
// normals, tangents and winding, texture coordinates, materials, lights,
// cameras, the "gltf" shape, and a glTF scene rendering the same bits as the
// equivalent pathlab scene.
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/gltf_loader.h"
#include "core/scene_loader.h"
#include "reference/reference_tracer.h"

#include "tests/gltf_writer.h"
#include "tests/temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::GltfWriter;

class Gltf : public test::TempDirTest {
 protected:
  // Writes `w` as name.gltf (embedded), name.glb and name-ext.gltf + .bin,
  // loads each and checks that they agree; returns the first.
  GltfContent load_all(const GltfWriter& w, const std::string& name, const GltfOptions& options = {}) const {
    GltfWriter::write(dir_ / (name + ".gltf"), w.embedded());
    GltfWriter::write(dir_ / (name + ".glb"), w.glb());
    w.write_external(dir_ / (name + "-ext.gltf"), name + ".bin");
    GltfContent a = load_gltf(dir_ / (name + ".gltf"), options);
    for (const char* other : {".glb", "-ext.gltf"}) {
      const GltfContent b = load_gltf(dir_ / (name + other), options);
      EXPECT_EQ(a.primitives.size(), b.primitives.size()) << other;
      for (std::size_t i = 0; i < std::min(a.primitives.size(), b.primitives.size()); ++i) {
        EXPECT_EQ(a.primitives[i].mesh.positions, b.primitives[i].mesh.positions) << other;
        EXPECT_EQ(a.primitives[i].mesh.triangles, b.primitives[i].mesh.triangles) << other;
      }
    }
    return a;
  }
  std::string error_of(const GltfWriter& w, const std::string& name) const {
    GltfWriter::write(dir_ / name, w.embedded());
    try {
      load_gltf(dir_ / name);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
};

GltfWriter quad(int index_type) {
  GltfWriter w;
  const int pos = w.add(test::kQuadPositions, test::kGltfFloat, "VEC3", 3);
  int idx;
  if (index_type == test::kGltfByte) idx = w.add(std::vector<std::uint8_t>{0, 1, 2, 0, 2, 3}, index_type, "SCALAR", 1);
  else if (index_type == test::kGltfShort) idx = w.add(std::vector<std::uint16_t>{0, 1, 2, 0, 2, 3}, index_type, "SCALAR", 1);
  else idx = w.add(std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}, index_type, "SCALAR", 1);
  w.mesh({{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}});
  w.node({{"mesh", 0}});
  return w;
}

TEST_F(Gltf, EveryIndexTypeInEveryContainer) {
  for (const int type : {test::kGltfByte, test::kGltfShort, test::kGltfUint}) {
    const GltfContent c = load_all(quad(type), "quad" + std::to_string(type));
    ASSERT_EQ(c.primitives.size(), 1u);
    const TriangleMesh& m = c.primitives[0].mesh;
    ASSERT_EQ(m.positions.size(), 4u);
    EXPECT_EQ(m.positions[2], vec3(1, 1, 0));
    EXPECT_EQ(m.triangles, (std::vector<glm::uvec3>{{0, 1, 2}, {0, 2, 3}}));
    EXPECT_FALSE(m.has_normals());
  }
}

// Positions and normals interleaved (stride 24) behind 8 bytes of something
// else: read through byteStride and both byteOffsets.
TEST_F(Gltf, InterleavedAttributesWithStrideAndOffsets) {
  GltfWriter w;
  std::vector<float> data(2, 7.0f);  // 8 bytes of padding before the first vertex
  for (int v = 0; v < 4; ++v) {
    for (int k = 0; k < 3; ++k) data.push_back(test::kQuadPositions[static_cast<std::size_t>(3 * v + k)] + static_cast<float>(v));
    for (int k = 0; k < 3; ++k) data.push_back(k == 2 ? 1.0f : 0.0f);
  }
  const int view = w.view(data.data(), data.size() * sizeof(float), 24);
  const int pos = w.accessor(view, test::kGltfFloat, 4, "VEC3", 8);
  const int nrm = w.accessor(view, test::kGltfFloat, 4, "VEC3", 20);
  w.mesh({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}}});  // not indexed: one triangle + 1 unused vertex
  w.node({{"mesh", 0}});
  const GltfContent c = load_all(w, "stride");
  ASSERT_EQ(c.primitives.size(), 1u);
  const TriangleMesh& m = c.primitives[0].mesh;
  ASSERT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.positions[1], vec3(2, 1, 1));
  EXPECT_EQ(m.positions[3], vec3(3, 4, 3));
  EXPECT_EQ(m.normals[3], vec3(0, 0, 1));
  EXPECT_EQ(m.triangles, (std::vector<glm::uvec3>{{0, 1, 2}}));
}

// Strip and fan keep the winding: every triangle faces +z.
TEST_F(Gltf, StripsAndFansAndSkippedLines) {
  GltfWriter w;
  const int pos = w.add(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0}, test::kGltfFloat, "VEC3", 3);
  const int fan = w.add(test::kQuadPositions, test::kGltfFloat, "VEC3", 3);
  w.mesh({{{"attributes", {{"POSITION", pos}}}, {"mode", 5}},
          {{"attributes", {{"POSITION", fan}}}, {"mode", 6}},
          {{"attributes", {{"POSITION", fan}}}, {"mode", 1}}});
  w.node({{"mesh", 0}});
  const GltfContent c = load_all(w, "strip");
  ASSERT_EQ(c.primitives.size(), 2u);
  EXPECT_EQ(c.primitives[0].mesh.triangles.size(), 3u);
  EXPECT_EQ(c.primitives[1].mesh.triangles.size(), 2u);
  for (const GltfPrimitive& p : c.primitives) {
    Shape s;
    s.mesh = p.mesh;
    for (std::uint32_t t = 0; t < p.mesh.triangles.size(); ++t) EXPECT_GT(triangle_normal(s, t).z, 0.99f) << p.description;
  }
  bool warned = false;
  for (const std::string& line : c.warnings) warned = warned || line.find("points or lines skipped") != std::string::npos;
  EXPECT_TRUE(warned);
}

// Parent TRS (translate, 90 degrees about z, scale) above a child matrix
// that mirrors x and scales y by 2: positions, normals (inverse transpose),
// tangents (with w flipped by the mirror) and the front side, in closed form.
TEST_F(Gltf, HierarchyTransformsNormalsTangentsAndWinding) {
  GltfWriter w;
  const int pos = w.add(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}, test::kGltfFloat, "VEC3", 3);
  const float s = std::sqrt(1.0f / 3.0f);
  // A normal with a y component, so that the non-uniform scale matters.
  const int nrm = w.add(std::vector<float>{s, s, s, s, s, s, s, s, s}, test::kGltfFloat, "VEC3", 3);
  const int tan = w.add(std::vector<float>{1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1}, test::kGltfFloat, "VEC4", 4);
  w.mesh({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}, {"TANGENT", tan}}}}});
  const float h = std::sqrt(0.5f);
  w.node({{"translation", {1, 2, 3}}, {"rotation", {0, 0, h, h}}, {"scale", {3, 3, 3}}, {"children", {1}}});
  // Column-major: x -> -x, y -> 2y.
  w.node({{"mesh", 0}, {"matrix", {-1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}});
  const GltfContent c = load_all(w, "tree");
  ASSERT_EQ(c.primitives.size(), 1u);
  const TriangleMesh& m = c.primitives[0].mesh;
  // (1,0,0) -> child (-1,0,0) -> scale (-3,0,0) -> rotate z 90 (0,-3,0) -> + (1,2,3).
  EXPECT_NEAR(glm::distance(m.positions[1], vec3(1, -1, 3)), 0.0f, 1e-5f);
  // (0,1,0) -> (0,2,0) -> (0,6,0) -> (-6,0,0) -> (-5,2,3).
  EXPECT_NEAR(glm::distance(m.positions[2], vec3(-5, 2, 3)), 0.0f, 1e-5f);
  // Normal (1,1,1)/sqrt3: the inverse transpose of diag(-1,2,1) gives
  // (-1,0.5,1) (the plain matrix would give (-1,2,1)), the rotation
  // (-0.5,-1,1).
  EXPECT_NEAR(glm::distance(m.normals[0], glm::normalize(vec3(-0.5f, -1, 1))), 0.0f, 1e-5f);
  // Tangent (1,0,0) -> (-1,0,0) -> (0,-1,0); mirrored, so w = -1.
  EXPECT_NEAR(glm::distance(vec3(m.tangents[0]), vec3(0, -1, 0)), 0.0f, 1e-5f);
  EXPECT_EQ(m.tangents[0].w, -1.0f);
  // The face's front stays on the side of the normal.
  Shape shape;
  shape.mesh = m;
  EXPECT_GT(glm::dot(triangle_normal(shape, 0), m.normals[0]), 0.0f);
}

TEST_F(Gltf, TextureCoordinatesFloatAndNormalizedIntegersWithVFlipped) {
  GltfWriter w;
  const int pos = w.add(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}, test::kGltfFloat, "VEC3", 3);
  const int uv_f = w.add(std::vector<float>{0, 0, 1, 0.2f, 0.5f, 1}, test::kGltfFloat, "VEC2", 2);
  const int uv_b = w.add(std::vector<std::uint8_t>{0, 0, 255, 51, 0, 255}, test::kGltfByte, "VEC2", 2, true);
  const int uv_s = w.add(std::vector<std::uint16_t>{0, 0, 65535, 13107, 0, 65535}, test::kGltfShort, "VEC2", 2, true);
  for (const int uv : {uv_f, uv_b, uv_s})
    w.mesh({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}}});
  for (int i = 0; i < 3; ++i) w.node({{"mesh", i}});
  const GltfContent c = load_all(w, "uv");
  ASSERT_EQ(c.primitives.size(), 3u);
  for (const GltfPrimitive& p : c.primitives) {
    ASSERT_EQ(p.mesh.uvs.size(), 3u);
    EXPECT_EQ(p.mesh.uvs[0], vec2(0, 1));  // glTF's top-left is pathlab's (0, 1)
    EXPECT_NEAR(p.mesh.uvs[1].x, 1.0f, 1e-6f);
    EXPECT_NEAR(p.mesh.uvs[1].y, 0.8f, 1e-6f);
    EXPECT_NEAR(p.mesh.uvs[2].y, 0.0f, 1e-6f);
  }
}

TEST_F(Gltf, MaterialsMapOntoDisney) {
  GltfWriter w = quad(test::kGltfShort);
  w.doc["meshes"][0]["primitives"].push_back(w.doc["meshes"][0]["primitives"][0]);
  w.doc["meshes"][0]["primitives"][0]["material"] = 0;
  w.doc["materials"] = json::array(
      {{{"name", "Gold"},
        {"pbrMetallicRoughness", {{"baseColorFactor", {1.0, 0.8, 0.25, 0.5}}, {"metallicFactor", 0.75}, {"roughnessFactor", 0.3},
                                  {"baseColorTexture", {{"index", 0}}}}},
        {"emissiveFactor", {0.5, 0.25, 0}},
        {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}},
        {"doubleSided", true}}});
  const GltfContent c = load_all(w, "mat");
  ASSERT_EQ(c.primitives.size(), 2u);
  ASSERT_EQ(c.materials.size(), 2u);
  const GltfMaterial& gold = c.materials[c.primitives[0].material];
  EXPECT_EQ(gold.gltf_name, "Gold");
  EXPECT_EQ(gold.material.name, "mat.gltf/Gold");
  EXPECT_EQ(gold.material.type, MaterialType::Disney);
  EXPECT_EQ(gold.material.disney.base_color, Spectrum(1.0f, 0.8f, 0.25f));
  EXPECT_EQ(gold.material.disney.metallic, 0.75f);
  EXPECT_EQ(gold.material.disney.roughness, 0.3f);
  EXPECT_EQ(gold.material.disney.specular, 0.5f);
  EXPECT_EQ(gold.material.emission, Spectrum(2.0f, 1.0f, 0.0f));
  EXPECT_TRUE(gold.double_sided);
  EXPECT_TRUE(gold.material.two_sided_emission);
  EXPECT_FALSE(gold.material.one_sided);
  // No material: glTF's default (base colour 1, metallic 1, roughness 1).
  const GltfMaterial& plain = c.materials[c.primitives[1].material];
  EXPECT_EQ(plain.material.name, "mat.gltf/(default)");
  EXPECT_EQ(plain.material.disney.base_color, Spectrum(1.0f));
  EXPECT_EQ(plain.material.disney.metallic, 1.0f);
  EXPECT_EQ(plain.material.disney.roughness, 1.0f);
  EXPECT_FALSE(plain.double_sided);
  EXPECT_TRUE(plain.material.one_sided);
  EXPECT_FALSE(plain.material.two_sided_emission);
  std::string all;
  for (const std::string& line : c.warnings) all += line + "\n";
  EXPECT_NE(all.find("ignored (not supported yet): alpha (rendered opaque), baseColorTexture"), std::string::npos) << all;
}

TEST_F(Gltf, PointLightCameraAndTheDirectScene) {
  GltfWriter w = quad(test::kGltfByte);
  w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  w.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "point"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 8.0}}, {{"type", "spot"}, {"spot", json::object()}}};
  w.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"aspectRatio", 2.0}, {"znear", 0.1}}}}};
  w.node({{"translation", {0, 3, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  w.node({{"translation", {0, 0, 4}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  // Turned 90 degrees about y: looks down -x.
  const float h = std::sqrt(0.5f);
  w.node({{"translation", {5, 0.5, 0.5}}, {"rotation", {0, h, 0, h}}, {"camera", 0}});
  const GltfContent c = load_all(w, "lit");
  ASSERT_EQ(c.point_lights.size(), 1u);
  EXPECT_EQ(c.point_lights[0].position, vec3(0, 3, 0));
  EXPECT_EQ(c.point_lights[0].intensity, Spectrum(8.0f, 4.0f, 2.0f));
  ASSERT_EQ(c.cameras.size(), 1u);
  EXPECT_NEAR(glm::distance(c.cameras[0].desc.position, vec3(5, 0.5, 0.5)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(c.cameras[0].desc.look_at, vec3(4, 0.5, 0.5)), 0.0f, 1e-6f);
  EXPECT_NEAR(c.cameras[0].desc.fov_y_degrees, 0.5f * 180.0f / 3.14159265f, 1e-4f);

  const Scene s = load_scene(dir_ / "lit.glb");
  EXPECT_EQ(s.film.width, 960);
  EXPECT_EQ(s.film.height, 480);
  EXPECT_EQ(s.camera.position, c.cameras[0].desc.position);
  EXPECT_FALSE(s.environment.has_value());
  EXPECT_EQ(s.shapes.size(), 1u);
  std::string all;
  for (const std::string& line : s.warnings) all += line + "\n";
  EXPECT_NE(all.find("spot and directional lights are not supported yet"), std::string::npos) << all;

  // Without camera and lights: the bounds framed, a white environment.
  GltfWriter::write(dir_ / "bare.gltf", quad(test::kGltfByte).embedded());
  const Scene bare = load_scene(dir_ / "bare.gltf");
  EXPECT_EQ(bare.film.width, 640);
  EXPECT_EQ(bare.environment, Spectrum(1.0f));
  EXPECT_EQ(bare.camera.look_at, vec3(0.5f, 0.5f, 0.0f));
  EXPECT_GT(bare.camera.position.z, 1.0f);
}

std::string scene_json(const std::string& shapes, const std::string& materials = "") {
  return R"({"pathlab_scene": 1, "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0]},
    "materials": {"white": {"type": "diffuse"}, "lamp": {"type": "emissive", "radiance": 1})" + materials + R"(},
    "shapes": [)" + shapes + "]}";
}

TEST_F(Gltf, SceneShapeWithMaterialOverrides) {
  GltfWriter w = quad(test::kGltfShort);
  w.doc["meshes"][0]["primitives"][0]["material"] = 0;
  w.doc["materials"] = {{{"name", "Paint"}}};
  GltfWriter::write(dir_ / "m.gltf", w.embedded());
  const fs::path file = dir_ / "s.json";
  const std::string xf = R"("transform": {"translate": [0, 0, 1]})";
  Scene own = parse_scene(scene_json(R"({"type": "gltf", "file": "m.gltf", )" + xf + "}"), file);
  ASSERT_EQ(own.shapes.size(), 1u);
  EXPECT_EQ(own.materials[own.shapes[0].material].name, "m.gltf/Paint");
  EXPECT_EQ(own.shapes[0].mesh.positions[2], vec3(1, 1, 1));
  Scene all = parse_scene(scene_json(R"({"type": "gltf", "file": "m.gltf", "material": "lamp"})"), file);
  EXPECT_EQ(all.materials[all.shapes[0].material].name, "lamp");
  Scene by_name = parse_scene(scene_json(R"({"type": "gltf", "file": "m.gltf", "materials": {"Paint": "white"}})"), file);
  EXPECT_EQ(by_name.materials[by_name.shapes[0].material].name, "white");
  try {
    parse_scene(scene_json(R"({"type": "gltf", "file": "m.gltf", "materials": {"Pain": "white"}})"), file);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("m.gltf has no material named 'Pain' (did you mean 'Paint'?)"), std::string::npos)
        << e.what();
  }
}

// A small Cornell-like glTF scene (floor, back wall, a mirrored box side,
// an emissive quad, a camera) and the same scene as pathlab JSON with OBJ
// meshes: the reference tracer renders the same bits.
TEST_F(Gltf, RendersTheSameBitsAsTheEquivalentPathlabScene) {
  struct Quad {
    std::vector<float> p;  // 4 corners, counter-clockwise seen from the front
    int material;
  };
  const std::vector<Quad> quads = {
      {{-1, -1, 1, 1, -1, 1, 1, -1, -1, -1, -1, -1}, 0},        // floor, faces +y
      {{-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1}, 1},        // back wall, faces +z
      {{-0.25f, 0.75f, -0.25f, 0.25f, 0.75f, -0.25f, 0.25f, 0.75f, 0.25f, -0.25f, 0.75f, 0.25f}, 2},  // lamp, faces -y
      {{-1, -1, 1, -1, -1, -1, -1, 1, -1, -1, 1, 1}, 0},        // left wall, faces +x
  };
  GltfWriter w;
  w.doc["materials"] = json::array(
      {{{"name", "white"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.75, 0.75, 0.75, 1}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.5}}}},
       {{"name", "red"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.75, 0.25, 0.25, 1}}, {"metallicFactor", 0.25}, {"roughnessFactor", 0.75}}}},
       {{"name", "lamp"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}}, {"emissiveFactor", {1, 1, 1}},
        {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 6.0}}}}}}});
  std::string obj_shapes;
  const int idx = w.add(std::vector<std::uint16_t>{0, 1, 2, 0, 2, 3}, test::kGltfShort, "SCALAR", 1);
  for (std::size_t q = 0; q < quads.size(); ++q) {
    const int pos = w.add(quads[q].p, test::kGltfFloat, "VEC3", 3);
    w.mesh({{{"attributes", {{"POSITION", pos}}}, {"indices", idx}, {"material", quads[q].material}}});
    // The mesh sits under a node translated by 0.5 in y; the OBJ has it added
    // (exact in float for these values).
    std::string obj;
    for (int v = 0; v < 4; ++v) {
      char line[128];
      std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", static_cast<double>(quads[q].p[static_cast<std::size_t>(3 * v)]),
                    static_cast<double>(quads[q].p[static_cast<std::size_t>(3 * v + 1)] + 0.5f),
                    static_cast<double>(quads[q].p[static_cast<std::size_t>(3 * v + 2)]));
      obj += line;
    }
    obj += "f 1 2 3\nf 1 3 4\n";
    GltfWriter::write(dir_ / ("q" + std::to_string(q) + ".obj"), obj);
    const char* names[] = {"white", "red", "lamp"};
    obj_shapes += std::string(q ? ", " : "") + R"({"type": "mesh", "file": "q)" + std::to_string(q) + R"(.obj", "material": ")" +
                  names[quads[q].material] + "\"}";
  }
  w.node({{"translation", {0, 0.5, 0}}, {"children", {1, 2, 3, 4}}});
  for (int q = 0; q < 4; ++q) w.node({{"mesh", q}});
  w.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.6981317007977318}, {"znear", 0.1}}}}};
  w.node({{"translation", {0, 0.5, 3.5}}, {"camera", 0}});
  w.doc["scenes"] = {{{"nodes", {0, 5}}}};
  w.doc["scene"] = 0;
  w.doc["materials"][2]["doubleSided"] = false;
  GltfWriter::write(dir_ / "box.glb", w.glb());
  const std::string json_text = R"({"pathlab_scene": 1,
    "camera": {"position": [0, 0.5, 3.5], "look_at": [0, 0.5, 2.5], "fov_y": 40},
    "materials": {
      "white": {"type": "disney", "base_color": 0.75, "metallic": 0, "roughness": 0.5, "one_sided": true},
      "red": {"type": "disney", "base_color": [0.75, 0.25, 0.25], "metallic": 0.25, "roughness": 0.75, "one_sided": true},
      "lamp": {"type": "disney", "base_color": 0, "metallic": 1, "roughness": 1, "emission": 6, "one_sided": true}},
    "shapes": [)" + obj_shapes + "]}";
  Scene from_gltf = load_scene(dir_ / "box.glb");
  Scene from_json = parse_scene(json_text, dir_ / "box.json");
  ASSERT_EQ(from_gltf.camera.fov_y_degrees, from_json.camera.fov_y_degrees);
  ASSERT_FALSE(from_gltf.environment.has_value());
  for (Scene* s : {&from_gltf, &from_json}) {
    s->film = FilmDesc{16, 12, FilterKind::Box};
    s->render.spp = 4;
    s->render.seed = 11;
  }
  const RenderSettings settings = from_json.render;
  const CompiledScene a(std::move(from_gltf)), b(std::move(from_json));
  const std::size_t n = 16 * 12 * 4;
  std::vector<FilmSample> sa(n), sb(n);
  ReferenceTracer(a, settings).render_batch(0, 4, sa);
  ReferenceTracer(b, settings).render_batch(0, 4, sb);
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(std::memcmp(&sa[i].L, &sb[i].L, sizeof(Spectrum)), 0) << i;
    sum += static_cast<double>(sa[i].L.x);
  }
  EXPECT_GT(sum, 0.0);  // something was lit
}

}  // namespace
}  // namespace pathlab
