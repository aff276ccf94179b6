// Recordings held in memory (awcc/recording.hpp): the Python module's arrays.
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <type_traits>
#include <vector>

#include "reader_support.hpp"

namespace awcc {

namespace {

namespace fs = std::filesystem;

using detail::reader_fail;

// Samples already in memory: read() copies the next frames out.
template <class Sample>
class MemoryRecording final : public Recording {
 public:
  MemoryRecording(std::vector<Sample> samples, int channels, double fs, double quantum, bool volts_known,
                  std::string name)
      : samples_(std::move(samples)) {
    const fs::path path(name);
    if (channels < 1) reader_fail(path, "no channel: give at least one array");
    const auto c = static_cast<std::size_t>(channels);
    if (samples_.size() % c != 0) {
      reader_fail(path, fmt::format("{} samples are not whole frames of {} channels; give arrays of one length",
                             samples_.size(), channels));
    }
    if (samples_.empty()) reader_fail(path, "no sample: the arrays are empty");
    if (!(fs > 0.0) || !std::isfinite(fs)) reader_fail(path, fmt::format("sampling rate {} Hz: give a positive rate", fs), "fs");
    if constexpr (std::is_floating_point_v<Sample>) {
      for (std::size_t i = 0; i < samples_.size(); ++i) {
        if (!std::isfinite(samples_[i])) {
          reader_fail(path, fmt::format("sample {} of channel {} is {}; remove or fill non-finite values first", i / c, i % c,
                                 samples_[i]), "volts");
        }
      }
    }
    info_.path = path;
    info_.format = "array";
    info_.description = std::is_floating_point_v<Sample> ? "array, float volts" : "array, 16-bit counts";
    info_.channels = channels;
    info_.fs = fs;
    info_.frames = static_cast<std::int64_t>(samples_.size() / c);
    info_.quantum = quantum;
    info_.volts_known = volts_known;
  }

  std::int64_t read(std::span<float> out, std::int64_t max_frames) override {
    const auto [from, n] = next(max_frames);
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(samples_[from + i] * scale());
    return advance(n);
  }
  void rewind() override { position_ = 0; }
  // No file to name: `name` only stands for one in messages.
  std::string sha256() override { return {}; }
  [[nodiscard]] bool has_int16() const override { return std::is_same_v<Sample, std::int16_t>; }
  std::int64_t read_int16(std::span<std::int16_t> out, std::int64_t max_frames) override {
    if constexpr (std::is_same_v<Sample, std::int16_t>) {
      const auto [from, n] = next(max_frames);
      std::copy_n(samples_.begin() + static_cast<std::ptrdiff_t>(from), n, out.begin());
      return advance(n);
    } else {
      return Recording::read_int16(out, max_frames);
    }
  }

 private:
  [[nodiscard]] double scale() const { return std::is_floating_point_v<Sample> ? 1.0 : info_.quantum; }
  // The first sample and the number of samples of the next max_frames frames.
  std::pair<std::size_t, std::size_t> next(std::int64_t max_frames) const {
    const auto frames = std::min<std::int64_t>(max_frames, info_.frames - position_);
    const auto c = static_cast<std::size_t>(info_.channels);
    return {static_cast<std::size_t>(position_) * c, static_cast<std::size_t>(std::max<std::int64_t>(frames, 0)) * c};
  }
  std::int64_t advance(std::size_t samples) {
    const auto frames = static_cast<std::int64_t>(samples / static_cast<std::size_t>(info_.channels));
    position_ += frames;
    return frames;
  }

  std::vector<Sample> samples_;
  std::int64_t position_ = 0;
};


}  // namespace

std::unique_ptr<Recording> memory_recording(std::vector<float> interleaved, int channels, double fs, std::string name) {
  return std::make_unique<MemoryRecording<float>>(std::move(interleaved), channels, fs, 0.0, true, std::move(name));
}

std::unique_ptr<Recording> memory_recording(std::vector<std::int16_t> interleaved, int channels, double fs,
                                            double quantum, bool volts_known, std::string name) {
  if (!(quantum > 0.0) || !std::isfinite(quantum)) {
    reader_fail(name, fmt::format("{} V per count: give a positive scale", quantum), "volts-per-count");
  }
  return std::make_unique<MemoryRecording<std::int16_t>>(std::move(interleaved), channels, fs, quantum, volts_known,
                                                         std::move(name));
}

}  // namespace awcc
