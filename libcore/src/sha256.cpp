#include "awcc/sha256.hpp"

#include <fmt/format.h>
#include <openssl/evp.h>

#include <algorithm>
#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>
#endif
#include <fstream>
#include <system_error>
#include <new>
#include <stdexcept>
#include <vector>

#include "awcc/errors.hpp"

namespace awcc {

struct Sha256::Context {
  EVP_MD_CTX* ctx;
};

void Sha256::Free::operator()(Context* c) const {
  EVP_MD_CTX_free(c->ctx);
  delete c;
}

Sha256::Sha256() : context_(new Context{EVP_MD_CTX_new()}) {
  if (!context_->ctx) throw std::bad_alloc();
  // Fails only when libcrypto has no SHA-256 at all (a FIPS provider
  // misconfigured): no digest can be trusted then.
  if (EVP_DigestInit_ex(context_->ctx, EVP_sha256(), nullptr) != 1) {
    throw std::runtime_error("libcrypto (OpenSSL) cannot compute SHA-256 here: check its installation");
  }
}

void Sha256::update(std::span<const std::uint8_t> data) {
  if (data.empty()) return;
  if (EVP_DigestUpdate(context_->ctx, data.data(), data.size()) != 1) {
    throw std::runtime_error("libcrypto (OpenSSL) failed while computing SHA-256");
  }
}

std::string Sha256::hex() {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  if (EVP_DigestFinal_ex(context_->ctx, digest, &size) != 1 || size != 32) {
    throw std::runtime_error("libcrypto (OpenSSL) failed while computing SHA-256");
  }
  std::string out;
  out.reserve(64);
  for (unsigned int i = 0; i < size; ++i) out += fmt::format("{:02x}", digest[i]);
  return out;
}

namespace {

// Hashes the file's bytes from `from` to its end into `digest`.
void hash_rest(const std::filesystem::path& path, std::uint64_t from, Sha256& digest) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot read the file to hash it", path.string()));
  if (from > 0) {
    // Bytes already hashed that the file no longer holds: it changed while being read.
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    in.seekg(static_cast<std::streamoff>(from));
    if (ec || size < from || !in) {
      throw InputError(fmt::format("{}: the file became shorter while being read; read it again when it is complete",
                                   path.string()));
    }
  }
  std::vector<char> buffer(std::size_t{1} << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto n = static_cast<std::size_t>(in.gcount());
    if (n > 0) digest.update({reinterpret_cast<const std::uint8_t*>(buffer.data()), n});
  }
  if (in.bad()) throw InputError(fmt::format("{}: a read error while hashing the file", path.string()));
}

}  // namespace

std::string sha256_of_file(const std::filesystem::path& path) {
  Sha256 h;
  hash_rest(path, 0, h);
  return h.hex();
}

FileSha256::FileSha256(std::filesystem::path path, std::size_t in_flight)
    : path_(std::move(path)), in_flight_limit_(in_flight) {
  try {
    worker_ = std::thread([this] { work(); });
  } catch (const std::system_error&) {
    // No thread to be had (a process limit): nothing is copied, hex() reads the file.
    in_flight_limit_ = 0;
    done_ = true;
  }
}

FileSha256::~FileSha256() {
  if (!worker_.joinable()) return;
  stop_ = true;
  {
    std::lock_guard lock(mutex_);
    finishing_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

void FileSha256::saw(std::uint64_t offset, std::span<const std::uint8_t> bytes) {
  const std::uint64_t end = offset + bytes.size();
  if (end <= queued_) return;  // seen before (a second pass)
  // A long gap ahead of the cursor (a trailing chunk parsed before the data):
  // left for the reading to reach, or for hex().
  const std::uint64_t claimed = claimed_.load(std::memory_order_acquire);
  if (offset > queued_ && offset - queued_ > gap_read_now && offset > claimed) return;
  const std::uint64_t from = std::max({offset, queued_, claimed});
  queued_ = end;
  if (from >= end) return;  // hashed already, or being read ahead
  const auto fresh = bytes.subspan(static_cast<std::size_t>(from - offset));
  // Small reads (a FLAC decoder's) gather into one piece, so that handing
  // pieces over costs little against hashing them.
  if (!filling_.bytes.empty() && filling_.offset + filling_.bytes.size() != from) hand_on();
  {
    std::unique_lock lock(mutex_);
    if (done_ || in_flight_ + fresh.size() > in_flight_limit_) {
      // Not copied: the hashing thread reads them itself, as soon as it is
      // free (the piece being filled first, so that it is queued before).
      lock.unlock();
      hand_on();
      lock.lock();
      not_copied_to_ = end;
      const bool wake = waiting_;
      lock.unlock();
      if (wake) changed_.notify_all();
      return;
    }
    in_flight_ += fresh.size();
    if (filling_.bytes.empty() && !spare_.empty()) {
      filling_.bytes = std::move(spare_.back());
      spare_.pop_back();
    }
  }
  if (filling_.bytes.empty()) filling_.offset = from;
  filling_.bytes.insert(filling_.bytes.end(), fresh.begin(), fresh.end());  // the copy is the reader's cost
  if (filling_.bytes.size() >= piece_bytes) hand_on();
}

void FileSha256::hand_on() {
  if (filling_.bytes.empty()) return;
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(filling_));
  }
  filling_ = Piece{};
  changed_.notify_all();
}

bool FileSha256::hash_file(std::uint64_t to, FileRead how) {
  const std::uint64_t from = hashed_;
  // One stream for every call (the read-ahead calls this every chunk_bytes):
  // opened once, by the hashing thread or, after it, by hex()'s caller.
  if (!file_.is_open()) {
    file_.open(path_, std::ios::binary);
    if (!file_) throw InputError(fmt::format("{}: cannot read the file to hash it", path_.string()));
    buffer_.resize(chunk_bytes);
  }
  std::error_code ec;
  const auto size = std::filesystem::file_size(path_, ec);
  // Bytes seen by the reader that the file no longer holds: it changed while being read.
  if (ec || size < from || (how != FileRead::ahead && to != std::uint64_t(-1) && size < to)) {
    throw InputError(fmt::format("{}: the file became shorter while being read; read it again when it is complete",
                                 path_.string()));
  }
  file_.clear();  // an earlier call may have read to the end
  file_.seekg(static_cast<std::streamoff>(from));
  std::uint64_t at = from;
  bool stopped = false;
  while (file_ && at < to) {
    if (how != FileRead::to_the_end && stop_.load(std::memory_order_relaxed)) {
      stopped = true;
      break;
    }
    const auto want = static_cast<std::streamsize>(std::min<std::uint64_t>(buffer_.size(), to - at));
    file_.read(buffer_.data(), want);
    const auto n = static_cast<std::size_t>(file_.gcount());
    if (n == 0) break;
    digest_.update({reinterpret_cast<const std::uint8_t*>(buffer_.data()), n});
    at += n;
  }
  read_again_ += at - from;
  hashed_ = at;
  if (stopped) return false;
  if (file_.bad()) throw InputError(fmt::format("{}: a read error while hashing the file", path_.string()));
  if (to != std::uint64_t(-1) && at != to) {
    if (how == FileRead::ahead) return false;  // the file's end
    throw InputError(fmt::format("{}: the file became shorter while being read; read it again when it is complete",
                                 path_.string()));
  }
  return true;
}

void FileSha256::hash_piece(const Piece& piece) {
  const std::uint64_t end = piece.offset + piece.bytes.size();
  if (end <= hashed_) return;  // read from the file already
  if (piece.offset > hashed_) hash_file(piece.offset, FileRead::to_the_end);  // a gap, or bytes not copied
  digest_.update(std::span<const std::uint8_t>(piece.bytes).subspan(static_cast<std::size_t>(hashed_ - piece.offset)));
  hashed_ = end;
}

void FileSha256::work() {
#if defined(__linux__)
  // The lowest priority, for this thread alone (class comment). SCHED_IDLE
  // rather than nice 19: the scheduler counts a core that runs only
  // SCHED_IDLE threads as idle, so the reader thread, woken, goes there at
  // once; at nice 19 it was woken onto the processing's core and the two
  // took turns on it. Neither needs a privilege; if both fail the hash runs
  // at the caller's priority.
  const sched_param lowest{};
  if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &lowest) != 0) {
    (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 19);
  }
#endif
  try {
    for (;;) {
      Piece piece;
      std::uint64_t to = 0;
      FileRead how = FileRead::stoppable;
      {
        std::unique_lock lock(mutex_);
        // Reading ahead of the reader only once it has stopped copying (a
        // file larger than the bytes in flight): a small file is hashed
        // from the reader's copies alone.
        const auto ahead = [&] { return not_copied_to_ > 0 && !at_end_; };
        waiting_ = true;
        changed_.wait(lock, [&] { return finishing_ || !queue_.empty() || not_copied_to_ > hashed_ || ahead(); });
        waiting_ = false;
        if (finishing_) break;  // hex() hashes the rest
        if (!queue_.empty() && queue_.front().offset <= hashed_) {
          piece = std::move(queue_.front());
          queue_.pop_front();
        } else if (!queue_.empty() || not_copied_to_ > hashed_) {
          // Bytes no piece holds, up to the next piece or to the last byte not copied.
          to = queue_.empty() ? not_copied_to_ : queue_.front().offset;
        } else {
          how = FileRead::ahead;
          to = hashed_ + chunk_bytes;
          claimed_.store(to, std::memory_order_release);  // before the bytes are read: saw() copies none of them
        }
      }
      if (piece.bytes.empty()) {
        const bool whole = hash_file(to, how);
        claimed_.store(std::max(claimed_.load(std::memory_order_relaxed), hashed_), std::memory_order_release);
        if (!whole) {
          if (how != FileRead::ahead || stop_) break;
          std::lock_guard lock(mutex_);
          at_end_ = true;
        }
        continue;
      }
      hash_piece(piece);
      claimed_.store(std::max(claimed_.load(std::memory_order_relaxed), hashed_), std::memory_order_release);
      {
        std::lock_guard lock(mutex_);
        in_flight_ -= piece.bytes.size();
        piece.bytes.clear();
        spare_.push_back(std::move(piece.bytes));
      }
    }
  } catch (...) {
    std::lock_guard lock(mutex_);
    error_ = std::current_exception();
  }
  std::lock_guard lock(mutex_);
  done_ = true;  // saw() copies nothing more
}

std::string FileSha256::hex() {
  if (worker_.joinable()) {
    hand_on();
    stop_ = true;
    {
      std::lock_guard lock(mutex_);
      finishing_ = true;
    }
    changed_.notify_all();
    worker_.join();
    if (error_) std::rethrow_exception(error_);
  }
  // What the hashing thread did not reach, here: the pieces still queued
  // (in file order: each continues the cursor), then the rest of the file.
  hashed_in_background_ = hashed_;
  for (const auto& piece : queue_) hash_piece(piece);
  queue_.clear();
  hash_file(std::uint64_t(-1), FileRead::to_the_end);
  // Read ahead to a file's end that the reader later found further on: the
  // file was cut while being read.
  if (hashed_ < queued_) {
    throw InputError(fmt::format("{}: the file became shorter while being read; read it again when it is complete",
                                 path_.string()));
  }
  return digest_.hex();
}

}  // namespace awcc
