#pragma once
// Where tests write scratch files and find the repository and shared data.

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace pdp_test {

inline std::filesystem::path source_dir() { return PDP_SOURCE_DIR; }

/// A scratch folder for this test binary (created on first use).
inline std::filesystem::path temp_dir() {
  const char* env = std::getenv("PDP_TEST_TMP");
  std::filesystem::path p = env ? env : (std::filesystem::temp_directory_path() / "pdp-tests");
  std::filesystem::create_directories(p);
  return p;
}

/// A scratch file owned by the running test: ctest runs tests of one binary
/// in parallel processes, so two tests must never write the same name.
inline std::filesystem::path test_file(const std::string& name) {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string owner = test ? std::string(test->test_suite_name()) + "." + test->name() + "." : "";
  return temp_dir() / (owner + name);
}

}  // namespace pdp_test
