// `pathlab check` from the command line: exit codes and what it writes.
#include "apps/cli/cli.h"
#include "tests/temp_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

namespace pathlab {
namespace {

int run(std::vector<std::string> args, std::string* err_text = nullptr) {
  args.insert(args.begin(), "pathlab");
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const int code = cli::run(static_cast<int>(argv.size()), argv.data(), out, err);
  if (err_text) *err_text = err.str();
  return code;
}

const std::string kScenes = std::string(PATHLAB_SOURCE_DIR) + "/analytic-scenes/";

TEST(CheckCli, PassesAnAnalyticSceneAndPrintsTheVerdict) {
  const test::ScopedTempDir folder("check-cli");
  const std::filesystem::path dir = folder.path() / "out";
  std::string err;
  EXPECT_EQ(run({"check", kScenes + "furnace-sphere.json", "--spp", "16", "--resolution", "8x8", "--out", dir.string()}, &err), 0)
      << err;
  EXPECT_NE(err.find("PASS"), std::string::npos) << err;
  EXPECT_NE(err.find("pathlab trace-pixel"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(dir)) << "nothing is written when the check passes";
}

// With a firefly control on, check reports the bias it introduces.
TEST(CheckCli, ReportsTheBiasOfFireflyControls) {
  const test::ScopedTempDir folder("check-clamp");
  std::string err;
  run({"check", kScenes + "sphere-in-environment.json", "--spp", "16", "--resolution", "8x8", "--clamp", "0.5", "--out",
       (folder.path() / "out").string()},
      &err);
  EXPECT_NE(err.find("firefly controls on (clamp 0.5"), std::string::npos) << err;
  EXPECT_NE(err.find("relative energy removed"), std::string::npos) << err;
  EXPECT_NE(err.find("measured bias vs the analytic image: -"), std::string::npos) << err;
}

// Refusals exit 2. (The failing path, exit 1 with images written, needs a
// planted fault: tests/test_faults.cpp.)
TEST(CheckCli, RefusesScenesItCannotCheck) {
  std::string err;
  EXPECT_EQ(run({"check", std::string(PATHLAB_SOURCE_DIR) + "/scenes/cornell-box.json", "--spp", "1"}, &err), 2);
  EXPECT_NE(err.find("names no analytic model"), std::string::npos) << err;
  EXPECT_EQ(run({"check"}, &err), 2);
  EXPECT_NE(err.find("needs a scene file"), std::string::npos) << err;
  EXPECT_EQ(run({"check", kScenes + "mirror-sphere-gray-room.json", "--max-depth", "3", "--spp", "1"}, &err), 2);
  EXPECT_NE(err.find("perfect mirror"), std::string::npos) << err;
}

}  // namespace
}  // namespace pathlab
