#pragma once
// SHA-256 (FIPS 180-4) of files, so that every output names the exact inputs
// it was made from. Computed by the system's libcrypto (OpenSSL), which uses
// the CPU's SHA instructions where there are some (docs/performance.md).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <filesystem>
#include <fstream>
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
/// a header the reader skips). Bytes seen further ahead of the cursor (a
/// trailing chunk parsed before the data) are left for the reading to reach.
///
/// The hashing thread runs at the lowest priority (on Linux, where a thread
/// has a scheduling policy of its own): it uses a core only when the reading
/// and the processing leave one idle, never takes one from them. Once the
/// reader has gone beyond the bytes in flight (a large file), the hashing
/// thread also reads ahead of the reader, so that an idle core is never left
/// waiting for the reading; the reader then copies nothing it has reached.
/// hex() stops the thread and hashes what it has not reached on the calling
/// thread, so a busy machine (a sweep on every core) costs no more than
/// hashing after the processing. The digest is always sha256_of_file's (a
/// file found shorter than the bytes read is refused). saw() is called from
/// one thread at a time; hex() after the reading.
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
  /// After hex(): the bytes read from the file itself rather than taken
  /// from the reader's copies.
  [[nodiscard]] std::uint64_t read_again() const { return read_again_; }
  /// After hex(): the bytes the hashing thread hashed before hex() (the rest
  /// was hashed by hex()'s caller).
  [[nodiscard]] std::uint64_t hashed_in_background() const { return hashed_in_background_; }

 private:
  struct Piece {
    std::uint64_t offset;
    std::vector<std::uint8_t> bytes;
  };
  static constexpr std::size_t piece_bytes = std::size_t{1} << 20;  // reads gathered before handing on
  // Bytes hashed between two looks at stop_: a stop waits for at most one
  // such chunk (0.1 ms at 2 GB/s).
  static constexpr std::size_t chunk_bytes = std::size_t{1} << 18;
  void hand_on();  // the piece being filled, to the hashing thread
  void work();
  enum class FileRead { to_the_end, stoppable, ahead };
  // Hashes the file's bytes [hashed_, to) (to = -1: to the end), read from
  // the file. Returns false when stop_ ends it early (stoppable, ahead) or
  // the file ends before `to` (ahead: not an error there).
  bool hash_file(std::uint64_t to, FileRead how);
  void hash_piece(const Piece& piece);  // the bytes of a piece not hashed yet (a gap before it from the file)

  std::filesystem::path path_;
  std::size_t in_flight_limit_;
  Sha256 digest_;                       // the hashing thread's
  std::uint64_t hashed_ = 0;            // the hashing thread's
  std::uint64_t read_again_ = 0;        // the hashing thread's
  std::uint64_t hashed_in_background_ = 0;
  std::uint64_t queued_ = 0;            // the reader's cursor
  // Below this offset every byte the reader saw is handed on or will not be
  // copied: the hashing thread may read from the file what no piece holds.
  std::uint64_t not_copied_to_ = 0;
  bool at_end_ = false;                 // the hashing thread read ahead to the file's end
  // Bytes below this offset are hashed, or being read ahead from the file:
  // saw() copies none of them.
  std::atomic<std::uint64_t> claimed_{0};
  std::atomic<bool> stop_{false};       // hex() or the destructor: the hashing thread stops
  Piece filling_;                       // the reader's: copies not yet handed on
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Piece> queue_;
  std::vector<std::vector<std::uint8_t>> spare_;  // buffers to reuse
  std::size_t in_flight_ = 0;
  bool finishing_ = false, done_ = false, waiting_ = false;
  std::exception_ptr error_;
  std::ifstream file_;                  // hash_file's: the hashing thread's, then hex()'s caller's
  std::vector<char> buffer_;            // hash_file's
  std::thread worker_;
};

}  // namespace awcc
