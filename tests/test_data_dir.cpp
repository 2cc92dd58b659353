// "$data/..." in a scene names a file of the data directory: the folder the
// build was configured with, or $PATHLAB_DATA_DIR when that is set
// (core/data_dir.h). No fetched data needed: the tests make their own.
#include "core/data_dir.h"
#include "core/error.h"
#include "core/scene_loader.h"

#include "tests/temp_dir.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace pathlab {
namespace {

namespace fs = std::filesystem;

// Sets an environment variable for one test and restores it afterwards.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() { had_ ? ::setenv(name_, old_.c_str(), 1) : ::unsetenv(name_); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

class DataDirectory : public test::TempDirTest {};

std::string mesh_scene(const std::string& file) {
  return R"({"pathlab_scene": 1, "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
  "materials": {"m": {"type": "diffuse", "albedo": 0.5}, "l": {"type": "emissive", "radiance": 1}},
  "shapes": [{"type": "mesh", "file": ")" + file + R"(", "material": "m"},
             {"type": "sphere", "center": [0, 3, 0], "radius": 0.5, "material": "l"}]})";
}

TEST_F(DataDirectory, PrefixResolvesToTheEnvironmentVariable) {
  fs::create_directories(dir_ / "meshes");
  std::ofstream(dir_ / "meshes" / "t.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const ScopedEnv env("PATHLAB_DATA_DIR", dir_.string());
  EXPECT_EQ(data_directory(), dir_);
  EXPECT_EQ(resolve_scene_path("/scenes", "$data/meshes/t.obj"), dir_ / "meshes" / "t.obj");
  EXPECT_EQ(resolve_scene_path("/scenes", "meshes/t.obj"), fs::path("/scenes/meshes/t.obj"));
  // "$datafoo/" and a "$data" in the middle are ordinary relative names.
  EXPECT_EQ(resolve_scene_path("/scenes", "$datafoo/t.obj"), fs::path("/scenes/$datafoo/t.obj"));
  const Scene scene = parse_scene(mesh_scene("$data/meshes/t.obj"), "/nowhere/scene.json");
  ASSERT_EQ(scene.shapes.size(), 2u);
  EXPECT_EQ(scene.shapes[0].mesh.triangles.size(), 1u);
}

TEST_F(DataDirectory, MissingDataFileSaysWhereTheDataDirectoryIs) {
  const ScopedEnv env("PATHLAB_DATA_DIR", (dir_ / "empty").string());
  try {
    (void)parse_scene(mesh_scene("$data/meshes/nothing.ply"), "s.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("s.json:3:"), std::string::npos) << what;
    EXPECT_NE(what.find("/shapes/0/file"), std::string::npos) << what;
    EXPECT_NE(what.find((dir_ / "empty" / "meshes" / "nothing.ply").string() + " does not exist"), std::string::npos)
        << what;
    EXPECT_NE(what.find("(from PATHLAB_DATA_DIR)"), std::string::npos) << what;
    EXPECT_NE(what.find("tools/fetch-data.sh"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace pathlab
