#pragma once
// Reading a recording one block ahead on a second thread, so that decoding
// (FLAC) or copying from the page cache overlaps with binarising the block
// before. For the library's own use; not installed, not a stable interface.
//
// Blocks come out in file order and each is exactly what a direct read would
// have returned, so results do not depend on whether the thread is used. A
// reader's error is thrown by next() where the direct read would have thrown
// it: after the blocks before it.

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <span>
#include <system_error>
#include <thread>
#include <vector>

namespace awcc::detail {

template <class Sample>
class ReadAhead {
 public:
  /// read(out, max_frames) fills out with up to max_frames frames and returns
  /// how many (0 at the end). With `threaded` false every block is read in next().
  using ReadFn = std::function<std::int64_t(std::span<Sample>, std::int64_t)>;

  ReadAhead(ReadFn read, std::int64_t block_frames, std::size_t stride, bool threaded)
      : read_(std::move(read)), block_frames_(block_frames), stride_(stride), threaded_(threaded) {
    // Without the thread one slot is all there is to fill.
    for (std::size_t k = 0; k < (threaded_ ? slots : 1); ++k) {
      slots_[k].data.resize(static_cast<std::size_t>(block_frames) * stride);
    }
    if (threaded_) {
      try {
        producer_ = std::thread([this] { produce(); });
      } catch (const std::system_error&) {
        threaded_ = false;  // no thread to be had (a process limit): read in next() instead
      }
    }
  }
  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;
  ~ReadAhead() {
    if (!threaded_) return;
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    producer_.join();
  }

  /// The next block: its samples (frames x stride), empty at the end. Valid until the next call.
  std::span<const Sample> next() {
    if (!threaded_) {
      Slot& s = slots_[0];
      const std::int64_t n = read_(s.data, block_frames_);
      return std::span<const Sample>(s.data.data(), used(n));
    }
    std::unique_lock lock(mutex_);
    if (ended_) return {};
    if (holding_) {
      slots_[consumer_].full = false;
      consumer_ = (consumer_ + 1) % slots;
      holding_ = false;
      changed_.notify_all();
    }
    changed_.wait(lock, [&] { return slots_[consumer_].full; });
    Slot& s = slots_[consumer_];
    if (s.error) std::rethrow_exception(s.error);
    holding_ = true;
    ended_ = s.frames == 0;
    return std::span<const Sample>(s.data.data(), used(s.frames));
  }

 private:
  static constexpr std::size_t slots = 3;
  struct Slot {
    std::vector<Sample> data;
    std::int64_t frames = 0;
    bool full = false;
    std::exception_ptr error;
  };

  std::size_t used(std::int64_t frames) const { return static_cast<std::size_t>(frames) * stride_; }

  void produce() {
    for (std::size_t i = 0;; i = (i + 1) % slots) {
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return stop_ || !slots_[i].full; });
        if (stop_) return;
      }
      Slot& s = slots_[i];
      std::int64_t n = 0;
      std::exception_ptr error;
      try {
        n = read_(s.data, block_frames_);
      } catch (...) {
        error = std::current_exception();
      }
      {
        std::lock_guard lock(mutex_);
        s.frames = n;
        s.error = error;
        s.full = true;
      }
      changed_.notify_all();
      if (n == 0 || error) return;  // the end (or an error) is the last block
    }
  }

  ReadFn read_;
  std::int64_t block_frames_;
  std::size_t stride_;
  bool threaded_;
  Slot slots_[slots];
  std::mutex mutex_;
  std::condition_variable changed_;
  std::size_t consumer_ = 0;
  bool holding_ = false;
  bool ended_ = false;
  bool stop_ = false;
  std::thread producer_;
};

}  // namespace awcc::detail
