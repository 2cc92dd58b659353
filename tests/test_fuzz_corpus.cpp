// Every file of every fuzz target's corpus (fuzz/corpus/<name>/: the seeds
// and each crasher the fuzzers found, kept once fixed) fed through the
// target's own entry point (fuzz/fuzz_target.h), without libFuzzer. A target
// swallows InputError, the answer bad input must get; any other exception
// fails the case here, and a crash or sanitizer report ends the process, so
// a fixed crash that comes back fails the suite in every build.
#include "fuzz/fuzz_target.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;

struct Case {
  const char* name;
  fuzz::Target target;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class FuzzCorpus : public ::testing::TestWithParam<Case> {};

std::vector<fs::path> corpus_files(const std::string& name) {
  std::vector<fs::path> files;
  const fs::path folder = fs::path(PATHLAB_SOURCE_DIR) / "fuzz" / "corpus" / name;
  if (!fs::is_directory(folder)) return files;
  for (const fs::directory_entry& e : fs::directory_iterator(folder))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

TEST_P(FuzzCorpus, EveryInputIsLoadedOrRefusedWithAnInputError) {
  const std::vector<fs::path> files = corpus_files(GetParam().name);
  ASSERT_GE(files.size(), 3u) << "fuzz/corpus/" << GetParam().name << " has fewer than 3 seeds";
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.string());
    std::ifstream in(file, std::ios::binary);
    std::vector<char> bytes(fs::file_size(file));
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(in) << "cannot read " << file;
    const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
    try {
      EXPECT_EQ(GetParam().target(data, bytes.size()), 0);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not an InputError: " << e.what();
    } catch (...) {
      ADD_FAILURE() << "an exception that is not a std::exception";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzCorpus,
                         ::testing::Values(Case{"scene", fuzz::scene}, Case{"ply", fuzz::ply}, Case{"obj", fuzz::obj},
                                           Case{"gltf", fuzz::gltf}, Case{"partial_film", fuzz::partial_film},
                                           Case{"envmap", fuzz::envmap}),
                         [](const ::testing::TestParamInfo<Case>& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace pathlab
