#pragma once
// SHA-256 (FIPS 180-4) of files, so that every output names the exact inputs
// it was made from.

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace awcc {

class Sha256 {
 public:
  Sha256();
  void update(std::span<const std::uint8_t> data);
  /// The digest as 64 lowercase hexadecimal digits; the object is spent.
  std::string hex();

 private:
  void block(const std::uint8_t* p);
  std::array<std::uint32_t, 8> h_;
  std::array<std::uint8_t, 64> buffer_{};
  std::size_t used_ = 0;
  std::uint64_t length_ = 0;  // bytes
};

/// The SHA-256 of a file's bytes (read in blocks). Throws InputError when it
/// cannot be read.
std::string sha256_of_file(const std::filesystem::path& path);

}  // namespace awcc
