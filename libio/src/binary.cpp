// Binary layouts (awcc/recording.hpp): the UQ LabVIEW .dat (two int32
// counts, then int16 frames) and headerless raw files in a stated layout.
#include <bit>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <vector>

#include "awcc/sha256.hpp"
#include "reader_support.hpp"

namespace awcc {

std::string_view to_string(SampleType type) {
  switch (type) {
    case SampleType::int16: return "int16";
    case SampleType::int32: return "int32";
    case SampleType::float32: return "float32";
    case SampleType::float64: return "float64";
  }
  return "?";
}

namespace detail {

namespace {

namespace fs = std::filesystem;

// The file's size (open_recording found it readable).
std::uintmax_t file_bytes(const fs::path& path) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec) reader_fail(path, fmt::format("cannot read: {}", ec.message()));
  return size;
}

// ---------------------------------------------------------------------------
// Binary layouts: UQ .dat and raw.


std::size_t sample_size(SampleType t) {
  switch (t) {
    case SampleType::int16: return 2;
    case SampleType::int32: return 4;
    case SampleType::float32: return 4;
    case SampleType::float64: return 8;
  }
  return 2;
}

class BinaryRecording final : public Recording {
 public:
  BinaryRecording(const fs::path& path, RecordingInfo info, RawLayout layout)
      : layout_(layout), in_(path, std::ios::binary) {
    info_ = std::move(info);
    if (!in_) reader_fail(path, "cannot open for reading");
    frame_bytes_ = sample_size(layout.sample_type) * static_cast<std::size_t>(layout.channels);
    swap_ = (layout.byte_order == ByteOrder::big) != (std::endian::native == std::endian::big);
    rewind();
  }

  std::int64_t read(std::span<float> out, std::int64_t max_frames) override {
    const std::int64_t n = std::min(max_frames, info_.frames - position_);
    if (n <= 0) return 0;
    bytes_.resize(static_cast<std::size_t>(n) * frame_bytes_);
    in_.read(bytes_.data(), static_cast<std::streamsize>(bytes_.size()));
    if (in_.gcount() != static_cast<std::streamsize>(bytes_.size())) {
      reader_fail(info_.path, fmt::format("the data ends early, after frame {} of {}: the file is truncated", position_,
                                   info_.frames));
    }
    saw(bytes_.data(), bytes_.size());
    const std::size_t count = static_cast<std::size_t>(n) * static_cast<std::size_t>(layout_.channels);
    const auto scale = static_cast<float>(layout_.volts_per_count);
    const char* p = bytes_.data();
    switch (layout_.sample_type) {
      case SampleType::int16:
        if (!swap_) {
          for (std::size_t i = 0; i < count; ++i) {
            std::int16_t v;
            std::memcpy(&v, p + 2 * i, 2);
            out[i] = static_cast<float>(v) * scale;
          }
        } else {
          for (std::size_t i = 0; i < count; ++i) out[i] = static_cast<float>(load<std::int16_t>(p + 2 * i, true)) * scale;
        }
        break;
      case SampleType::int32:
        for (std::size_t i = 0; i < count; ++i) {
          out[i] = static_cast<float>(static_cast<double>(load<std::int32_t>(p + 4 * i, swap_)) * layout_.volts_per_count);
        }
        break;
      case SampleType::float32:
        for (std::size_t i = 0; i < count; ++i) out[i] = load<float>(p + 4 * i, swap_) * scale;
        check_finite(info_.path, out.first(count), position_, layout_.channels);
        break;
      case SampleType::float64:
        for (std::size_t i = 0; i < count; ++i) {
          const double v = load<double>(p + 8 * i, swap_) * layout_.volts_per_count;
          out[i] = static_cast<float>(v);
          if (!std::isfinite(v) || std::fabs(v) > 3.0e38) out[i] = std::numeric_limits<float>::quiet_NaN();
        }
        check_finite(info_.path, out.first(count), position_, layout_.channels);
        break;
    }
    position_ += n;
    return n;
  }

  void rewind() override {
    in_.clear();
    in_.seekg(layout_.header_bytes);
    position_ = 0;
  }

  [[nodiscard]] bool has_int16() const override { return layout_.sample_type == SampleType::int16; }

  std::int64_t read_int16(std::span<std::int16_t> out, std::int64_t max_frames) override {
    const std::int64_t n = std::min(max_frames, info_.frames - position_);
    if (n <= 0) return 0;
    const std::size_t count = static_cast<std::size_t>(n) * static_cast<std::size_t>(layout_.channels);
    in_.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(count * 2));
    if (in_.gcount() != static_cast<std::streamsize>(count * 2)) {
      reader_fail(info_.path, fmt::format("the data ends early, after frame {} of {}: the file is truncated", position_,
                                   info_.frames));
    }
    saw(out.data(), count * 2);  // as stored, before any swap
    if (swap_) {
      for (std::size_t i = 0; i < count; ++i) {
        const auto u = static_cast<std::uint16_t>(out[i]);
        out[i] = static_cast<std::int16_t>(static_cast<std::uint16_t>((u >> 8) | (u << 8)));
      }
    }
    position_ += n;
    return n;
  }

  void hash_while_reading() override { digest_ = std::make_unique<FileSha256>(info_.path); }

  std::string sha256() override {
    if (!digest_) return Recording::sha256();
    const auto digest = std::move(digest_);
    return digest->hex();
  }

 private:
  // The bytes just read, as stored: they end at the stream's position.
  void saw(const void* bytes, std::size_t n) {
    if (!digest_) return;
    const auto end = static_cast<std::uint64_t>(layout_.header_bytes) + static_cast<std::uint64_t>(position_) * frame_bytes_ + n;
    digest_->saw(end - n, {static_cast<const std::uint8_t*>(bytes), n});
  }

  std::unique_ptr<FileSha256> digest_;  // while hashing as read
  RawLayout layout_;
  std::ifstream in_;
  std::size_t frame_bytes_ = 0;
  bool swap_ = false;
  std::int64_t position_ = 0;
  std::vector<char> bytes_;
};

}  // namespace

std::unique_ptr<Recording> open_uq_dat(const fs::path& path, const ReaderOptions& options) {
  const std::uintmax_t size = file_bytes(path);
  if (size < 8) reader_fail(path, fmt::format("{} bytes is too short for a UQ .dat header (8 bytes)", size));
  std::ifstream in(path, std::ios::binary);
  char header[8];
  in.read(header, 8);
  const auto rows = load<std::int32_t>(header, std::endian::native == std::endian::big);
  const auto channels = load<std::int32_t>(header + 4, std::endian::native == std::endian::big);
  // LabVIEW writes the header of an acquisition stopped before its first
  // sample: a recording with no samples, not another layout.
  if (rows == 0 && channels > 0 && channels <= 64 && size == 8) {
    reader_fail(path, fmt::format("the .dat header says 0 rows of {} channels and no sample follows: the acquisition "
                                  "recorded nothing; record again",
                                  channels));
  }
  if (rows <= 0 || channels <= 0 || channels > 64) {
    reader_fail(path, fmt::format("the .dat header says {} rows and {} channels, which is not a UQ .dat header; if the file "
                           "is headerless, read it as a raw file with its layout",
                           rows, channels), "format");
  }
  const std::uintmax_t expected = 8 + static_cast<std::uintmax_t>(rows) * static_cast<std::uintmax_t>(channels) * 2;
  if (size < expected) {
    reader_fail(path, fmt::format("the .dat header announces {} rows x {} channels ({} bytes) but the file has {} bytes: it is "
                           "truncated; recover the full recording",
                           rows, channels, expected, size));
  }
  if (size > expected) {
    reader_fail(path, fmt::format("the .dat header announces {} rows x {} channels ({} bytes) but the file has {} bytes: the "
                           "header does not describe the data; check the acquisition or read it as a raw file with its layout",
                           rows, channels, expected, size), "format");
  }
  RawLayout layout;
  layout.sample_type = SampleType::int16;
  layout.channels = channels;
  layout.header_bytes = 8;
  layout.volts_per_count = options.volts_per_count > 0.0 ? options.volts_per_count : 5.0 / 32768.0;
  RecordingInfo info;
  info.path = path;
  info.description = "UQ LabVIEW .dat (int16, +/-5 V)";
  info.channels = channels;
  info.fs = options.fs;
  if (!(info.fs > 0.0)) {
    reader_fail(path, "a .dat file does not store its sampling rate; state it (e.g. 20 kHz)", "fs");
  }
  info.frames = rows;
  info.quantum = layout.volts_per_count;
  info.volts_known = true;
  auto recording = std::make_unique<BinaryRecording>(path, std::move(info), layout);
  check_interleaving(
      *recording, "the .dat header's channel count (bytes 4-7)",
      [&](int n) {
        const auto samples = static_cast<std::int64_t>(rows) * channels;
        return fmt::format(
            "correct the header to {} channels{}, or read the file as raw (format raw, raw-channels {}, "
            "raw-header 8 bytes)",
            n, samples % n == 0 ? fmt::format(" and {} rows", samples / n) : std::string(), n);
      },
      "format");
  return recording;
}

std::unique_ptr<Recording> open_raw(const fs::path& path, const ReaderOptions& options) {
  const std::uintmax_t size = file_bytes(path);
  const RawLayout& layout = options.raw;
  if (layout.channels <= 0 || layout.channels > 1024) reader_fail(path, fmt::format("raw layout: {} channels is not possible", layout.channels));
  if (layout.header_bytes < 0 || static_cast<std::uintmax_t>(layout.header_bytes) > size) {
    reader_fail(path, fmt::format("raw layout: {} header bytes to skip, but the file has {} bytes", layout.header_bytes, size));
  }
  if (!(options.fs > 0.0)) reader_fail(path, "a raw file does not store its sampling rate; state it (e.g. 500 kHz)", "fs");
  const std::uintmax_t data = size - static_cast<std::uintmax_t>(layout.header_bytes);
  const std::uintmax_t frame = sample_size(layout.sample_type) * static_cast<std::uintmax_t>(layout.channels);
  if (data % frame != 0) {
    reader_fail(path, fmt::format("raw layout: {} data bytes are not a whole number of {}-byte frames ({} channels of {}); "
                           "check the raw layout (channels, sample type, header bytes)",
                           data, frame, layout.channels, to_string(layout.sample_type)), "raw-channels,raw-type,raw-header");
  }
  if (data == 0) reader_fail(path, "the raw file holds no samples");
  RecordingInfo info;
  info.path = path;
  info.description = fmt::format("raw {} {}-endian, {} channels", to_string(layout.sample_type),
                                 layout.byte_order == ByteOrder::little ? "little" : "big", layout.channels);
  info.channels = layout.channels;
  info.fs = options.fs;
  info.frames = static_cast<std::int64_t>(data / frame);
  const bool integer = layout.sample_type == SampleType::int16 || layout.sample_type == SampleType::int32;
  info.quantum = integer ? layout.volts_per_count : 0.0;
  info.volts_known = true;
  auto recording = std::make_unique<BinaryRecording>(path, std::move(info), layout);
  check_interleaving(
      *recording, "the stated raw layout (raw-channels)", [](int n) { return fmt::format("state raw-channels {}", n); },
      "raw-channels");
  return recording;
}

}  // namespace detail

}  // namespace awcc
