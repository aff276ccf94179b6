#pragma once
// SHA-256 (FIPS 180-4) of files, so that every output names the exact inputs
// it was made from. Computed by the system's libcrypto (OpenSSL), which uses
// the CPU's SHA instructions where there are some (docs/performance.md).

#include <cstdint>
#include <filesystem>
#include <memory>
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
  struct Context;  // libcrypto's, kept out of this header
  struct Free {
    void operator()(Context* c) const;
  };
  std::unique_ptr<Context, Free> context_;
};

/// The SHA-256 of a file's bytes (read in blocks). Throws InputError when it
/// cannot be read.
std::string sha256_of_file(const std::filesystem::path& path);

/// The SHA-256 of a whole file from the bytes a reader reads anyway, in
/// whatever order and however often it reads them: bytes that continue the
/// part hashed so far (the cursor) are hashed as they are seen; a short gap
/// before bytes seen ahead of the cursor (at most gap_read_now: a header the
/// reader skips) is read from the file then; bytes further ahead, or never
/// seen, are read from the file by hex(). So
/// the digest is always sha256_of_file's, and costs no second read when the
/// reader reads the file front to back. Not shared between threads: one
/// thread sees bytes at a time, and hex() comes after the reading.
class FileSha256 {
 public:
  static constexpr std::uint64_t gap_read_now = std::uint64_t{1} << 16;  // bytes
  explicit FileSha256(std::filesystem::path path);
  /// Bytes [offset, offset + bytes.size()) of the file, as just read.
  void saw(std::uint64_t offset, std::span<const std::uint8_t> bytes);
  /// The bytes hashed so far: the file's first hashed() bytes.
  [[nodiscard]] std::uint64_t hashed() const { return hashed_; }
  /// The whole file's digest, the bytes after the cursor read now; spent.
  /// Throws InputError when they cannot be read.
  std::string hex();

 private:
  std::filesystem::path path_;
  Sha256 digest_;
  std::uint64_t hashed_ = 0;
};

}  // namespace awcc
