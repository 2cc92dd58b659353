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
#include "tests/texture_util.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
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
        {"pbrMetallicRoughness", {{"baseColorFactor", {1.0, 0.8, 0.25, 0.5}}, {"metallicFactor", 0.75}, {"roughnessFactor", 0.3}}},
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
  // alphaMode OPAQUE (the default) ignores the factor's alpha.
  EXPECT_EQ(gold.material.alpha, 1.0f);
  EXPECT_EQ(all.find("alpha"), std::string::npos) << all;
}

// alphaMode onto the material's coverage (core/alpha.h): MASK cuts at
// alphaCutoff (0.5 by default), BLEND is the alpha itself, OPAQUE ignores it.
// With a base colour texture its alpha (channel 3, linear) times the factor
// is the coverage, a mask under MASK.
TEST_F(Gltf, AlphaModesMapOntoCoverage) {
  GltfWriter w = quad(test::kGltfShort);
  const json first = w.doc["meshes"][0]["primitives"][0];
  const auto factor = [](double a) { return json{{"baseColorFactor", {1, 1, 1, a}}}; };
  w.doc["materials"] = json::array({{{"alphaMode", "MASK"}, {"pbrMetallicRoughness", factor(0.5)}},
                                    {{"alphaMode", "MASK"}, {"alphaCutoff", 0.6}, {"pbrMetallicRoughness", factor(0.5)}},
                                    {{"alphaMode", "BLEND"}, {"pbrMetallicRoughness", factor(0.25)}},
                                    {{"alphaMode", "OPAQUE"}, {"pbrMetallicRoughness", factor(0.25)}},
                                    {{"alphaMode", "BLEND"},
                                     {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.5}}, {"baseColorTexture", {{"index", 0}}}}}},
                                    {{"alphaMode", "MASK"}, {"alphaCutoff", 0.4},
                                     {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.8}}, {"baseColorTexture", {{"index", 0}}}}}}});
  w.doc["meshes"][0]["primitives"] = json::array();
  for (int m = 0; m < 6; ++m) {
    json p = first;
    p["material"] = m;
    w.doc["meshes"][0]["primitives"].push_back(p);
  }
  test::write_image(dir_ / "base.png", 1, 1, 4, {1.0f, 1.0f, 1.0f, 0.5f}, OIIO::TypeDesc::UINT8);
  w.doc["images"] = json::array({{{"uri", "base.png"}}});
  w.doc["textures"] = json::array({{{"source", 0}}});
  const GltfContent c = load_all(w, "alpha");
  ASSERT_EQ(c.primitives.size(), 6u);
  const auto material = [&](int m) { return c.materials[c.primitives[static_cast<std::size_t>(m)].material].material; };
  const float expected[] = {1.0f, 0.0f, 0.25f, 1.0f, 0.5f, 1.0f};
  const float cutoff[] = {0.5f, 0.6f, -1.0f, -1.0f, -1.0f, 0.4f};
  for (int m = 0; m < 6; ++m) {
    EXPECT_EQ(material(m).alpha, expected[m]) << m;
    EXPECT_EQ(material(m).alpha_cutoff, cutoff[m]) << m;
    EXPECT_EQ(material(m).alpha_texture.has_value(), m >= 4) << m;
  }
  for (const int m : {4, 5}) {
    EXPECT_EQ(material(m).alpha_texture->channel, 3);
    EXPECT_EQ(material(m).alpha_texture->scale.x, m == 4 ? 0.5f : 0.8f);
  }
}

// Textures: base colour (an external PNG), metallic-roughness (a PNG in a
// buffer view), normal (a data URI), emissive (external, shared with base
// colour), each times its factor; a sampler's wrap mode; texCoord 1,
// KHR_texture_transform and occlusion warned about.
TEST_F(Gltf, MaterialsBringTheirTextures) {
  // 2x1 RGB images: base colour codes and metallic-roughness codes.
  test::write_image(dir_ / "base.png", 2, 1, 3, {1.0f, 0.5f, 0.0f, 0.2f, 0.4f, 0.6f}, OIIO::TypeDesc::UINT8);
  test::write_image(dir_ / "mr.png", 2, 1, 3, {0.0f, 0.4f, 1.0f, 0.0f, 0.8f, 0.2f}, OIIO::TypeDesc::UINT8);
  test::write_image(dir_ / "n.png", 1, 1, 3, {0.5f, 0.5f, 1.0f}, OIIO::TypeDesc::UINT8);
  const auto bytes = [&](const char* name) {
    std::ifstream in(dir_ / name, std::ios::binary);
    return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  GltfWriter w = quad(test::kGltfShort);
  const int uv = w.add(std::vector<float>{0, 1, 1, 1, 1, 0, 0, 0}, test::kGltfFloat, "VEC2", 2);
  w.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv;
  w.doc["meshes"][0]["primitives"][0]["material"] = 0;
  const std::vector<unsigned char> mr = bytes("mr.png");
  const int mr_view = w.view(mr.data(), mr.size());
  w.doc["images"] = json::array({{{"uri", "base.png"}},
                                 {{"bufferView", mr_view}, {"mimeType", "image/png"}},
                                 {{"uri", "data:image/png;base64," + GltfWriter::base64(bytes("n.png"))}}});
  w.doc["samplers"] = json::array({{{"wrapS", 33071}, {"wrapT", 33071}}});
  w.doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}, {{"source", 1}}, {{"source", 2}}});
  w.doc["materials"] = json::array(
      {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 1.0, 1.0, 1.0}}, {"metallicFactor", 0.5}, {"roughnessFactor", 0.8},
                                  {"baseColorTexture", {{"index", 0}}},
                                  {"metallicRoughnessTexture", {{"index", 1}, {"extensions", {{"KHR_texture_transform", json::object()}}}}}}},
        {"normalTexture", {{"index", 2}, {"scale", 0.5}}},
        {"emissiveTexture", {{"index", 0}}},
        {"emissiveFactor", {1.0, 0.5, 0.0}},
        {"occlusionTexture", {{"index", 0}, {"texCoord", 1}}}}});
  GltfWriter::write(dir_ / "tex.gltf", w.embedded());
  const GltfContent c = load_gltf(dir_ / "tex.gltf");
  // base.png once (sRGB for both base colour and emission), mr.png, n.png.
  ASSERT_EQ(c.images.size(), 3u);
  EXPECT_EQ(c.images[0].file, dir_ / "base.png");
  EXPECT_EQ(c.images[0].colorspace, TextureColorSpace::Srgb);
  EXPECT_EQ(c.images[1].colorspace, TextureColorSpace::Linear);
  EXPECT_EQ(c.images[2].colorspace, TextureColorSpace::Linear);
  const Material& m = c.materials[c.primitives[0].material].material;
  ASSERT_NE(m.texture_of(MaterialParam::BaseColor), nullptr);
  EXPECT_EQ(m.texture_of(MaterialParam::BaseColor)->texture.scale, Spectrum(0.5f, 1.0f, 1.0f));
  EXPECT_EQ(m.texture_of(MaterialParam::BaseColor)->texture.wrap, TextureWrap::Clamp);
  ASSERT_NE(m.texture_of(MaterialParam::Metallic), nullptr);
  EXPECT_EQ(m.texture_of(MaterialParam::Metallic)->texture.channel, 2);
  EXPECT_EQ(m.texture_of(MaterialParam::Metallic)->texture.scale, Spectrum(0.5f));
  ASSERT_NE(m.texture_of(MaterialParam::Roughness), nullptr);
  EXPECT_EQ(m.texture_of(MaterialParam::Roughness)->texture.channel, 1);
  EXPECT_EQ(m.texture_of(MaterialParam::Roughness)->texture.scale, Spectrum(0.8f));
  ASSERT_NE(m.texture_of(MaterialParam::Emission), nullptr);
  EXPECT_EQ(m.texture_of(MaterialParam::Emission)->texture.scale, Spectrum(1.0f, 0.5f, 0.0f));
  EXPECT_TRUE(m.emits());
  ASSERT_TRUE(m.normal_map.has_value());
  EXPECT_EQ(m.normal_map->scale, 0.5f);
  std::string all;
  for (const std::string& line : c.warnings) all += line + "\n";
  EXPECT_NE(all.find("KHR_texture_transform ignored"), std::string::npos) << all;
  EXPECT_NE(all.find("occlusionTexture"), std::string::npos) << all;

  // Through a scene: the lookups read the files' texels times the factors.
  GltfWriter::write(dir_ / "s.json", R"({"pathlab_scene": 1, "camera": {"position": [0.5, 0.5, 2], "look_at": [0.5, 0.5, 0]},
    "materials": {}, "shapes": [{"type": "gltf", "file": "tex.gltf"}]})");
  const CompiledScene compiled(load_scene(dir_ / "s.json"));
  ASSERT_TRUE(compiled.has_textures());
  const Material& sm = compiled.scene().materials[compiled.scene().shapes[0].material];
  const auto srgb = [](double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); };
  const TextureFootprint texel0{vec2(0.25f, 0.5f), 0.0f};
  const Spectrum base = compiled.textures()->color(sm.texture_of(MaterialParam::BaseColor)->texture, texel0);
  EXPECT_NEAR(base.x, 0.5, 1e-6);
  EXPECT_NEAR(base.y, srgb(128.0 / 255.0), 1e-6);
  EXPECT_NEAR(base.z, 0.0, 1e-6);
  EXPECT_NEAR(compiled.textures()->number(sm.texture_of(MaterialParam::Metallic)->texture, texel0), 0.5, 1e-6);
  EXPECT_NEAR(compiled.textures()->number(sm.texture_of(MaterialParam::Roughness)->texture, texel0), 0.8 * 0.4, 1e-6);
  // A hit reads them too (an untextured closure would have the factors' base colour).
  Surfel s;
  SurfaceParams params;
  ASSERT_TRUE(compiled.intersect(compiled.camera().generate_ray(vec2(128.0f, 128.0f), vec2(0.5f)), &s, {}, &params));
  EXPECT_EQ(s.params, &params);
  EXPECT_NE(params.closure.spec0, sm.closure.spec0);
}

TEST_F(Gltf, PunctualLightsCameraAndTheDirectScene) {
  const float h = std::sqrt(0.5f);
  GltfWriter w = quad(test::kGltfByte);
  w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  w.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "point"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 8.0}},
      {{"type", "spot"}, {"intensity", 2.0}, {"spot", {{"innerConeAngle", 0.25}, {"outerConeAngle", 0.5}}}},
      {{"type", "directional"}, {"color", {0.5, 1.0, 1.0}}, {"intensity", 3.0}}};
  w.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"aspectRatio", 2.0}, {"znear", 0.1}}}}};
  w.node({{"translation", {0, 3, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  w.node({{"translation", {0, 0, 4}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  // Turned -90 degrees about x: -z becomes -y (shining down).
  w.node({{"rotation", {-h, 0, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  // Turned 90 degrees about y: looks down -x.
  w.node({{"translation", {5, 0.5, 0.5}}, {"rotation", {0, h, 0, h}}, {"camera", 0}});
  const GltfContent c = load_all(w, "lit");
  ASSERT_EQ(c.delta_lights.size(), 3u);
  EXPECT_EQ(c.delta_lights[0].kind, DeltaLight::Kind::Point);
  EXPECT_EQ(c.delta_lights[0].position, vec3(0, 3, 0));
  EXPECT_EQ(c.delta_lights[0].intensity, Spectrum(8.0f, 4.0f, 2.0f));
  // A spot shines down the node's -z axis; cone angles are half-angles in radians.
  EXPECT_EQ(c.delta_lights[1].kind, DeltaLight::Kind::Spot);
  EXPECT_EQ(c.delta_lights[1].position, vec3(0, 0, 4));
  EXPECT_EQ(c.delta_lights[1].direction, vec3(0, 0, -1));
  EXPECT_EQ(c.delta_lights[1].intensity, Spectrum(2.0f));
  EXPECT_FLOAT_EQ(c.delta_lights[1].cos_inner, std::cos(0.25f));
  EXPECT_FLOAT_EQ(c.delta_lights[1].cos_outer, std::cos(0.5f));
  // Lux taken as W/m^2; the light travels down the node's -z axis.
  EXPECT_EQ(c.delta_lights[2].kind, DeltaLight::Kind::Directional);
  EXPECT_NEAR(glm::distance(c.delta_lights[2].direction, vec3(0, -1, 0)), 0.0f, 1e-6f);
  EXPECT_EQ(c.delta_lights[2].intensity, Spectrum(1.5f, 3.0f, 3.0f));
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
  EXPECT_EQ(all.find("lights"), std::string::npos) << all;
  EXPECT_EQ(s.delta_lights.size(), 3u);

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

// glTF materials: opaque metallic-roughness, and a black emitter of
// white emission times `strength`.
json pbr_material(const std::string& name, const std::vector<double>& rgb, double metallic, double roughness) {
  return {{"name", name},
          {"pbrMetallicRoughness",
           {{"baseColorFactor", {rgb[0], rgb[1], rgb[2], 1}}, {"metallicFactor", metallic}, {"roughnessFactor", roughness}}}};
}
json emitter_material(const std::string& name, double strength) {
  return {{"name", name},
          {"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
          {"emissiveFactor", {1, 1, 1}},
          {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", strength}}}}}};
}

// Every sample of both scenes (same film, spp and seed) by the reference
// tracer, with the second scene's settings.
std::pair<std::vector<FilmSample>, std::vector<FilmSample>> render_both(Scene first, Scene second) {
  const RenderSettings settings = second.render;
  const std::size_t n = static_cast<std::size_t>(second.film.width) * static_cast<std::size_t>(second.film.height) *
                        static_cast<std::size_t>(settings.spp);
  const CompiledScene a(std::move(first)), b(std::move(second));
  std::vector<FilmSample> sa(n), sb(n);
  ReferenceTracer(a, settings).render_batch(0, static_cast<std::uint32_t>(settings.spp), sa);
  ReferenceTracer(b, settings).render_batch(0, static_cast<std::uint32_t>(settings.spp), sb);
  return {std::move(sa), std::move(sb)};
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
  w.doc["materials"] = json::array({pbr_material("white", {0.75, 0.75, 0.75}, 0.0, 0.5),
                                     pbr_material("red", {0.75, 0.25, 0.25}, 0.25, 0.75), emitter_material("lamp", 6.0)});
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
  const auto [sa, sb] = render_both(std::move(from_gltf), std::move(from_json));
  const std::size_t n = sa.size();
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(std::memcmp(&sa[i].L, &sb[i].L, sizeof(Spectrum)), 0) << i;
    sum += static_cast<double>(sa[i].L.x);
  }
  EXPECT_GT(sum, 0.0);  // something was lit
}

// ------------------------------------------------------------ instancing

// A lopsided pyramid (the mirror shows), one-sided (a placement that lost
// the mirror's front would show its black back), smooth or flat shaded.
int add_pyramid(GltfWriter& w, int material, bool smooth = true) {
  const std::vector<float> p = {-0.3f, 0, -0.3f, 0.3f, 0, -0.3f, 0.3f, 0, 0.3f, -0.3f, 0, 0.3f, 0.1f, 0.5f, 0.05f};
  std::vector<float> n;
  for (std::size_t v = 0; v < 5; ++v) {
    const vec3 d = glm::normalize(vec3(p[3 * v], p[3 * v + 1], p[3 * v + 2]) - vec3(0.05f, 0.15f, 0.0f));
    n.insert(n.end(), {d.x, d.y, d.z});
  }
  const int pos = w.add(p, test::kGltfFloat, "VEC3", 3);
  json attributes = {{"POSITION", pos}};
  if (smooth) attributes["NORMAL"] = w.add(n, test::kGltfFloat, "VEC3", 3);
  const int idx = w.add(std::vector<std::uint16_t>{3, 2, 4, 2, 1, 4, 1, 0, 4, 0, 3, 4, 0, 1, 2, 0, 2, 3}, test::kGltfShort, "SCALAR", 1);
  return w.mesh({{{"attributes", attributes}, {"indices", idx}, {"material", material}}});
}

// A flat square of side 2 * half in y = 0, facing +y (or -y).
int add_square(GltfWriter& w, float half, bool up, int material) {
  const float h = half;
  const std::vector<float> p = up ? std::vector<float>{-h, 0, h, h, 0, h, h, 0, -h, -h, 0, -h}
                                  : std::vector<float>{-h, 0, -h, h, 0, -h, h, 0, h, -h, 0, h};
  const int pos = w.add(p, test::kGltfFloat, "VEC3", 3);
  const int idx = w.add(std::vector<std::uint16_t>{0, 1, 2, 0, 2, 3}, test::kGltfShort, "SCALAR", 1);
  return w.mesh({{{"attributes", {{"POSITION", pos}}}, {"indices", idx}, {"material", material}}});
}

// Column-major 4x4 of a mirror in x, then a translation.
json mirror_x_at(float x, float y, float z) { return {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, x, y, z, 1}; }

// The pyramid placed by three nodes under one rotated parent (plain, mirrored
// in x, scaled non-uniformly and turned), a floor placed once, and a lamp
// placed twice (emissive: stays copies).
GltfWriter three_pyramids(bool smooth = true, const json& scale = {1.5, 0.5, 1}) {
  GltfWriter w;
  w.doc["materials"] = json::array({pbr_material("white", {0.8, 0.8, 0.8}, 0.0, 0.6),
                                     pbr_material("red", {0.8, 0.3, 0.2}, 0.2, 0.4), emitter_material("lamp", 8.0)});
  const int pyramid = add_pyramid(w, 1, smooth), floor = add_square(w, 2.0f, true, 0), lamp = add_square(w, 0.25f, false, 2);
  const float s = std::sin(glm::radians(10.0f)), c = std::cos(glm::radians(10.0f));  // 20 degrees about y
  const float s45 = std::sin(glm::radians(22.5f)), c45 = std::cos(glm::radians(22.5f));
  w.node({{"translation", {0, 0.01, 0}}, {"rotation", {0, s, 0, c}}, {"children", {1, 2, 3}}});  // 0
  w.node({{"mesh", pyramid}, {"translation", {-0.8, 0, 0}}});                                     // 1
  w.node({{"mesh", pyramid}, {"matrix", mirror_x_at(0, 0, 0.3f)}});                               // 2
  w.node({{"mesh", pyramid}, {"translation", {0.8, 0, -0.2}}, {"rotation", {0, s45, 0, c45}}, {"scale", scale}});  // 3
  w.node({{"mesh", floor}});                                                                      // 4
  w.node({{"mesh", lamp}, {"translation", {-0.5, 1.5, 0}}});                                      // 5
  w.node({{"mesh", lamp}, {"translation", {0.5, 1.5, 0}}});                                       // 6
  w.doc["scenes"] = {{{"nodes", {0, 4, 5, 6}}}};
  w.doc["scene"] = 0;
  for (json& m : w.doc["materials"]) m["doubleSided"] = false;
  return w;
}

// The scene transform used below: instances must apply it after the nodes'.
mat4 scene_transform() {
  return glm::translate(mat4(1.0f), vec3(0.1f, -0.2f, 0.0f)) * glm::rotate(mat4(1.0f), glm::radians(15.0f), vec3(0, 1, 0)) *
         glm::scale(mat4(1.0f), vec3(1.1f));
}

std::size_t vertex_count(const Scene& s) {
  std::size_t n = 0;
  for (const Shape& shape : s.shapes) n += shape.mesh.positions.size();
  return n;
}

TEST_F(Gltf, MeshPlacedByThreeNodesIsOneGroupOfThreeInstances) {
  GltfOptions options;
  options.transform = scene_transform();
  const GltfContent c = load_all(three_pyramids(), "three", options);
  // The floor once; the lamp twice (it emits: copies stay lights).
  ASSERT_EQ(c.primitives.size(), 3u);
  EXPECT_NE(c.primitives[0].description.find("(node 4)"), std::string::npos) << c.primitives[0].description;
  ASSERT_EQ(c.groups.size(), 1u);
  EXPECT_EQ(c.groups[0].name, "three.gltf/mesh #0");
  ASSERT_EQ(c.groups[0].primitives.size(), 1u);
  EXPECT_EQ(c.groups[0].primitives[0].mesh.positions.size(), 5u);  // in mesh space, once
  EXPECT_EQ(c.groups[0].primitives[0].mesh.positions[4], vec3(0.1f, 0.5f, 0.05f));
  ASSERT_EQ(c.instances.size(), 3u);
  // to_world = the scene transform x the node's world matrix (parent x child).
  const float s = std::sin(glm::radians(10.0f)), co = std::cos(glm::radians(10.0f));
  const mat4 parent = glm::translate(mat4(1.0f), vec3(0, 0.01f, 0)) * glm::mat4_cast(glm::normalize(glm::quat(co, 0, s, 0)));
  const mat4 mirror = glm::translate(mat4(1.0f), vec3(0, 0, 0.3f)) * glm::scale(mat4(1.0f), vec3(-1, 1, 1));
  const vec3 p(0.3f, 0.2f, -0.1f);
  EXPECT_NEAR(glm::distance(vec3(c.instances[1].to_world * vec4(p, 1)), vec3(scene_transform() * parent * mirror * vec4(p, 1))), 0.0f, 1e-5f);
  EXPECT_LT(glm::determinant(mat3(c.instances[1].to_world)), 0.0f);
  EXPECT_NE(c.instances[2].description.find("/nodes/3 (mesh 0)"), std::string::npos) << c.instances[2].description;
  for (const Instance& inst : c.instances) EXPECT_EQ(inst.group, 0u);

  // Forced flattening: a copy per placement, as before instancing.
  options.flatten = true;
  const GltfContent flat = load_all(three_pyramids(), "three-flat", options);
  EXPECT_EQ(flat.primitives.size(), 6u);
  EXPECT_TRUE(flat.groups.empty());
  EXPECT_TRUE(flat.instances.empty());

  // As a scene's shape: the group's shapes in_group, the vertices stored once.
  const fs::path file = dir_ / "s.json";
  const Scene scene = parse_scene(scene_json(R"({"type": "gltf", "file": "three.glb"})"), file);
  ASSERT_EQ(scene.groups.size(), 1u);
  EXPECT_EQ(scene.groups[0].name, "three.glb/mesh #0");
  EXPECT_EQ(scene.instances.size(), 3u);
  ASSERT_EQ(scene.groups[0].shapes.size(), 1u);
  EXPECT_TRUE(scene.shapes[scene.groups[0].shapes[0]].in_group);
  EXPECT_EQ(vertex_count(scene), 4u + 4u + 4u + 5u);  // floor, two lamps, the pyramid once (not 3 x 5)
  // The same file twice: the second group named apart, instances offset.
  const Scene twice = parse_scene(
      scene_json(R"({"type": "gltf", "file": "three.glb"}, {"type": "gltf", "file": "three.gltf"}, {"type": "gltf", "file": "three.glb"})"),
      file);
  ASSERT_EQ(twice.groups.size(), 3u);
  EXPECT_EQ(twice.groups[2].name, "three.glb/mesh #0 (2)");
  ASSERT_EQ(twice.instances.size(), 9u);
  EXPECT_EQ(twice.instances[8].group, 2u);

  // Inside a scene group the file is flattened (instances are one level).
  const Scene grouped = parse_scene(R"({"pathlab_scene": 1, "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0]},
    "materials": {"white": {"type": "diffuse"}}, "shapes": [],
    "groups": {"g": [{"type": "gltf", "file": "three.glb", "material": "white"}]},
    "instances": [{"group": "g", "transforms": [{"translate": [0, 0, 0]}, {"translate": [5, 0, 0]}]}]})",
                                    file);
  ASSERT_EQ(grouped.groups.size(), 1u);
  EXPECT_EQ(grouped.groups[0].shapes.size(), 6u);
  EXPECT_EQ(grouped.instances.size(), 2u);
  for (const Shape& shape : grouped.shapes) EXPECT_TRUE(shape.in_group);
}

// glTF allows a node one parent: a second one is refused (every path would
// be a placement, 2^n for a chain of n doubled links), as is a scene root
// that is some node's child. Two nodes naming one mesh place it twice.
TEST_F(Gltf, NodesHaveOneParentAndMeshesArePlacedPerNode) {
  GltfWriter w;
  add_square(w, 1.0f, true, -1);
  w.doc["meshes"][0]["primitives"][0].erase("material");
  w.node({{"mesh", 0}});
  w.node({{"translation", {0, 1, 0}}, {"children", {0}}});
  w.node({{"translation", {0, 2, 0}}, {"children", {0}}});
  w.doc["scenes"] = {{{"nodes", {1, 2}}}};
  const auto refused = [&](const std::string& name, const std::string& words) {
    try {
      (void)load_all(w, name);
      ADD_FAILURE() << name << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused("dag", "/nodes/2/children/0: node 0 already has parent node 1 (glTF allows one parent per node)");
  w.doc["nodes"][2].erase("children");
  w.doc["nodes"][2]["mesh"] = 0;
  w.doc["scenes"] = {{{"nodes", {0, 1, 2}}}};
  refused("root", "/scenes/0/nodes/0: node 0 is a child of node 1, not a root");
  w.doc["scenes"] = {{{"nodes", {1, 2}}}};
  const GltfContent c = load_all(w, "two");
  EXPECT_TRUE(c.primitives.empty());
  EXPECT_EQ(c.groups.size(), 1u);
  ASSERT_EQ(c.instances.size(), 2u);
  EXPECT_EQ(vec3(c.instances[1].to_world[3]), vec3(0, 2, 0));
  // Placed once: a world-space copy, as ever.
  w.doc["scenes"] = {{{"nodes", {1}}}};
  const GltfContent once = load_all(w, "tree");
  EXPECT_EQ(once.primitives.size(), 1u);
  EXPECT_TRUE(once.groups.empty());
  EXPECT_EQ(once.primitives[0].mesh.positions[0], vec3(-1, 1, 1));
}

// Emitters stay lights: a mesh with an emitting material (the file's, or a
// scene material that overrides it) is copied; a scene material that
// replaces the emitter lets it be a group.
TEST_F(Gltf, MeshesThatAreLightsStayCopies) {
  GltfWriter::write(dir_ / "three.gltf", three_pyramids().embedded());
  const fs::path file = dir_ / "s.json";
  const Scene own = parse_scene(scene_json(R"({"type": "gltf", "file": "three.gltf"})"), file);
  EXPECT_EQ(own.groups.size(), 1u);  // the pyramid; the lamps are two shapes
  EXPECT_EQ(own.shapes.size(), 4u);
  const Scene lamp_everywhere = parse_scene(scene_json(R"({"type": "gltf", "file": "three.gltf", "material": "lamp"})"), file);
  EXPECT_TRUE(lamp_everywhere.groups.empty());
  EXPECT_EQ(lamp_everywhere.shapes.size(), 6u);
  const Scene red_lamp = parse_scene(
      scene_json(R"({"type": "gltf", "file": "three.gltf", "materials": {"red": "lamp", "lamp": "white"}})"), file);
  ASSERT_EQ(red_lamp.groups.size(), 1u);  // the lamps now, white
  EXPECT_EQ(red_lamp.materials[red_lamp.shapes[red_lamp.groups[0].shapes[0]].material].name, "white");
  EXPECT_EQ(red_lamp.instances.size(), 2u);
  // "light": false: not sampled, so it may be instanced.
  const Scene unsampled = parse_scene(
      scene_json(R"({"type": "gltf", "file": "three.gltf", "material": "glow"})", R"(, "glow": {"type": "emissive", "radiance": 1, "light": false})"),
      file);
  EXPECT_EQ(unsampled.groups.size(), 2u);
  // A scene group may not take a glTF group's name.
  try {
    parse_scene(R"({"pathlab_scene": 1, "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0]},
      "materials": {"white": {"type": "diffuse"}}, "shapes": [{"type": "gltf", "file": "three.gltf"}],
      "groups": {"three.gltf/mesh #0": [{"type": "box", "material": "white"}]}})",
                file);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is taken by a glTF mesh's group"), std::string::npos) << e.what();
  }
  // append_gltf refuses a group whose material is a light (the loader was
  // told otherwise by is_light).
  GltfOptions never;
  never.is_light = [](const GltfMaterial&) { return false; };
  const GltfContent all_grouped = load_gltf(dir_ / "three.gltf", never);
  ASSERT_EQ(all_grouped.groups.size(), 2u);
  Scene s = parse_scene(scene_json(R"({"type": "box", "material": "white"})"), file);
  const auto lamp = static_cast<std::uint32_t>(
      std::find_if(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.name == "lamp"; }) - s.materials.begin());
  ASSERT_TRUE(s.materials.at(lamp).emits());
  EXPECT_THROW(append_gltf(s, all_grouped, std::vector<std::optional<std::uint32_t>>(3, lamp)), InputError);
}

// A placement without an inverse (zero scale) is copied instead, losing its
// degenerate triangles with a warning that names the node; one beyond the
// float range is refused naming the node.
TEST_F(Gltf, SingularPlacementsAreCopiesAndOverflowIsRefused) {
  GltfWriter w;
  add_pyramid(w, -1);
  w.doc["meshes"][0]["primitives"][0].erase("material");
  w.node({{"mesh", 0}});
  w.node({{"mesh", 0}, {"translation", {2, 0, 0}}});
  w.node({{"mesh", 0}, {"scale", {0, 0, 0}}});
  const GltfContent c = load_all(w, "flat");
  EXPECT_EQ(c.groups.size(), 1u);
  EXPECT_EQ(c.instances.size(), 2u);
  EXPECT_TRUE(c.primitives.empty());
  std::string all;
  for (const std::string& line : c.warnings) all += line + "\n";
  EXPECT_NE(all.find("/meshes/0/primitives/0 (node 2): dropped 6 degenerate triangle(s) of 6"), std::string::npos) << all;
  w.doc["nodes"][2] = {{"mesh", 0}, {"scale", {1e30, 1e30, 1e30}}, {"children", {1}}};
  w.doc["nodes"][1]["scale"] = {1e30, 1e30, 1e30};
  w.doc["scenes"] = {{{"nodes", {0, 2}}}};
  const std::string error = error_of(w, "huge.gltf");
  EXPECT_NE(error.find("huge.gltf: /nodes/2: the transform moves vertices beyond the scene coordinate limit 1e16"), std::string::npos) << error;
}

// Just below pi the angle is 180 degrees as a float (tan(fov / 2) -2.3e7):
// held to the scene's fov_y limit, 179 degrees.
TEST_F(Gltf, ACameraFieldOfViewNearPiIsRefusedWithTheRange) {
  for (const double yfov : {3.141592652589793 - 1e-9, 3.13}) {
    GltfWriter w = quad(test::kGltfByte);
    w.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", yfov}, {"znear", 0.1}}}}};
    w.node({{"translation", {0, 0, 4}}, {"camera", 0}});
    const std::string error = error_of(w, "wide.gltf");
    EXPECT_NE(error.find("wide.gltf: /cameras/0/perspective/yfov: yfov "), std::string::npos) << error;
    EXPECT_NE(error.find(" is outside (0, 3.124139] radians (0 to 179 degrees"), std::string::npos) << error;
  }
}

// A node's transform that glTF does not allow is an error naming it: it used
// to be dropped (tinygltf leaves a malformed array empty) and the mesh placed
// as if it had none. A long but finite quaternion is normalised (in double).
TEST_F(Gltf, MalformedNodeTransformsAreRefused) {
  const auto error_with = [this](const nlohmann::json& node) {
    GltfWriter w;
    add_pyramid(w, -1);
    w.doc["meshes"][0]["primitives"][0].erase("material");
    w.node(node);
    return error_of(w, "bad.gltf");
  };
  const std::pair<nlohmann::json, std::string> cases[] = {
      {{{"mesh", 0}, {"matrix", {1, 0, 0}}}, "/nodes/0/matrix: expected an array of 16 numbers"},
      {{{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5, 0, 0, "x"}}}, "/nodes/0/matrix/15: expected a finite number"},
      {{{"mesh", 0}, {"matrix", {1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2}}}, "/nodes/0/matrix: not an affine transform"},
      {{{"mesh", 0}, {"translation", {0.5, 0}}}, "/nodes/0/translation: expected an array of 3 numbers"},
      {{{"mesh", 0}, {"scale", {1, "2", 1}}}, "/nodes/0/scale/1: expected a finite number"},
      {{{"mesh", 0}, {"rotation", {0, 0, 0, 0}}}, "/nodes/0/rotation: a rotation is a unit quaternion"},
      {{{"mesh", 0}, {"translation", {1, 0, 0}}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}},
       "/nodes/0: a node has either 'matrix' or"},
  };
  for (const auto& [node, expected] : cases) {
    const std::string error = error_with(node);
    EXPECT_NE(error.find("bad.gltf: " + expected), std::string::npos) << node.dump() << "\n" << error;
  }
  const auto placed_by = [&](const json& rotation, const std::string& name) {
    GltfWriter w;
    add_pyramid(w, -1);
    w.doc["meshes"][0]["primitives"][0].erase("material");
    w.node({{"mesh", 0}, {"rotation", rotation}});
    const GltfContent c = load_all(w, name);
    EXPECT_EQ(c.primitives.size(), 1u);
    return c.primitives.empty() ? std::vector<vec3>{} : c.primitives[0].mesh.positions;
  };
  const double h = std::sqrt(0.5);
  const std::vector<vec3> unit = placed_by({h, 0, 0, h}, "unit"), long_ = placed_by({1e30, 0, 0, 1e30}, "long");
  ASSERT_EQ(unit.size(), long_.size());
  for (std::size_t i = 0; i < unit.size(); ++i) EXPECT_LT(glm::length(unit[i] - long_[i]), 1e-6f) << i;
}

// The same file instanced and with flattening forced renders the same image
// with the same seed, up to float rounding of the hit points: the mirror,
// the parent and the scene transform must all reach the instances. Smooth
// normals only under a uniform scale: under a non-uniform one CompiledScene
// interpolates an instance's normals before transforming them, a copy's
// after (each normalised), which shades differently, not by rounding.
TEST_F(Gltf, InstancedRendersAsFlattened) {
  for (const bool smooth : {true, false}) {
    SCOPED_TRACE(smooth ? "smooth, uniform scale" : "flat, non-uniform scale");
    const GltfWriter w = smooth ? three_pyramids(true, {1.2, 1.2, 1.2}) : three_pyramids(false);
    GltfWriter::write(dir_ / "three.glb", w.glb());
    const auto scene = [&](bool flatten) {
      Scene s;
      s.camera.position = vec3(0.0f, 1.3f, 3.0f);
      s.camera.look_at = vec3(0.0f, 0.2f, 0.0f);
      s.camera.fov_y_degrees = 45.0f;
      s.film = FilmDesc{32, 24, FilterKind::Box};
      s.render.spp = 4;
      s.render.seed = 5;
      GltfOptions options;
      options.transform = scene_transform();
      options.flatten = flatten;
      append_gltf(s, load_gltf(dir_ / "three.glb", options));
      return s;
    };
    Scene instanced = scene(false), flat = scene(true);
    ASSERT_EQ(instanced.instances.size(), 3u);
    ASSERT_TRUE(flat.instances.empty());
    const auto [sa, sb] = render_both(std::move(instanced), std::move(flat));
    const std::size_t n = sa.size();
    std::size_t equal = 0;
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      bool same = true;
      for (int k = 0; k < 3; ++k)
        same = same && std::abs(sa[i].L[k] - sb[i].L[k]) <= 1e-4f * std::max(std::abs(sa[i].L[k]), std::abs(sb[i].L[k])) + 1e-6f;
      equal += same ? 1 : 0;
      sum += static_cast<double>(sb[i].L.x);
    }
    EXPECT_GT(sum, 0.0);
    EXPECT_GE(static_cast<double>(equal), 0.99 * static_cast<double>(n)) << n - equal << " of " << n << " samples differ";
  }
}
}  // namespace
}  // namespace pathlab
