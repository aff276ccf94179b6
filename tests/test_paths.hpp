#pragma once
// Where tests write scratch files and find the repository and shared data.

#include <cstdlib>
#include <filesystem>

namespace pdp_test {

inline std::filesystem::path source_dir() { return PDP_SOURCE_DIR; }

/// A scratch folder for this test binary (created on first use).
inline std::filesystem::path temp_dir() {
  const char* env = std::getenv("PDP_TEST_TMP");
  std::filesystem::path p = env ? env : (std::filesystem::temp_directory_path() / "pdp-tests");
  std::filesystem::create_directories(p);
  return p;
}

}  // namespace pdp_test
