// Fresh temporary folders for tests, removed afterwards.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>

namespace pathlab::test {

// A folder under the system's temporary folder, unique to this process and
// `tag`, empty when made and removed (with its contents) on destruction.
class ScopedTempDir {
 public:
  explicit ScopedTempDir(std::string_view tag)
      : path_(std::filesystem::temp_directory_path() /
              ("pathlab-" + std::string(tag) + "-" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScopedTempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A fixture giving each test its own folder `dir_`, named after the test.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    folder_.emplace(std::string(info->test_suite_name()) + "-" + info->name());
    dir_ = folder_->path();
  }
  void TearDown() override { folder_.reset(); }

  // Writes `bytes` to the file `name` in dir_ and returns its path.
  std::filesystem::path write(const std::string& name, const std::string& bytes) const {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  std::filesystem::path dir_;

 private:
  std::optional<ScopedTempDir> folder_;
};

}  // namespace pathlab::test
