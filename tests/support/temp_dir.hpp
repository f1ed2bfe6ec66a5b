// A temporary folder for a test's outputs, removed at the end of the test.
// SPDX-License-Identifier: MIT
#pragma once
#include <filesystem>
#include <random>
#include <string>

namespace terrapolis::test {

class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() / ("terrapolis-test-" + std::to_string(rd()) + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::string sample(const std::string& name) { return std::string(TERRAPOLIS_SAMPLES) + "/" + name; }

}  // namespace terrapolis::test
