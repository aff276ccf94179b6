#pragma once
// SHA-256 (FIPS 180-4) of files, so that every output names the exact inputs
// it was made from. Computed by the system's libcrypto (OpenSSL), which uses
// the CPU's SHA instructions where there are some (docs/performance.md).

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

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
/// whatever order and however often it reads them, computed on a thread of
/// its own so that the hash overlaps with the reading and with whatever
/// follows it. Bytes that continue those handed on so far (the cursor) are
/// copied into at most `in_flight` bytes of buffers for the hashing thread;
/// beyond that the reader is not held up: the hashing thread reads those
/// bytes from the file itself, as it does a short gap (at most gap_read_now:
/// a header the reader skips) and everything after the last bytes seen.
/// Bytes seen further ahead of the cursor (a trailing chunk parsed before the
/// data) are left for the reading to reach. So the digest is always
/// sha256_of_file's. saw() is called from one thread at a time; hex() after
/// the reading.
class FileSha256 {
 public:
  static constexpr std::uint64_t gap_read_now = std::uint64_t{1} << 16;       // bytes
  static constexpr std::size_t default_in_flight = std::size_t{4} << 20;      // bytes
  explicit FileSha256(std::filesystem::path path, std::size_t in_flight = default_in_flight);
  FileSha256(const FileSha256&) = delete;
  FileSha256& operator=(const FileSha256&) = delete;
  ~FileSha256();
  /// Bytes [offset, offset + bytes.size()) of the file, as just read.
  void saw(std::uint64_t offset, std::span<const std::uint8_t> bytes);
  /// The cursor: the file's first seen() bytes are handed on (copied, or
  /// left for the hashing thread to read).
  [[nodiscard]] std::uint64_t seen() const { return queued_; }
  /// The whole file's digest once the hashing thread is done; spent. Throws
  /// InputError when the file cannot be read (or became shorter).
  std::string hex();
  /// After hex(): the bytes the hashing thread read from the file itself
  /// rather than from the reader's copies.
  [[nodiscard]] std::uint64_t read_again() const { return read_again_; }

 private:
  struct Piece {
    std::uint64_t offset;
    std::vector<std::uint8_t> bytes;
  };
  static constexpr std::size_t piece_bytes = std::size_t{1} << 20;  // reads gathered before handing on
  void hand_on();  // the piece being filled, to the hashing thread
  void work();
  void hash_file(std::uint64_t from, std::uint64_t to);  // on the hashing thread; to = -1: the end

  std::filesystem::path path_;
  std::size_t in_flight_limit_;
  Sha256 digest_;                       // the hashing thread's
  std::uint64_t hashed_ = 0;            // the hashing thread's
  std::uint64_t read_again_ = 0;        // the hashing thread's
  std::uint64_t queued_ = 0;            // the reader's cursor
  Piece filling_;                       // the reader's: copies not yet handed on
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Piece> queue_;
  std::vector<std::vector<std::uint8_t>> spare_;  // buffers to reuse
  std::size_t in_flight_ = 0;
  bool finishing_ = false, abandon_ = false, done_ = false;
  std::exception_ptr error_;
  std::thread worker_;
};

}  // namespace awcc
