#include "awcc/recording.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <optional>
#include <sndfile.h>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "awcc/errors.hpp"
#include "awcc/order_statistics.hpp"
#include "awcc/pdpsim_layout.hpp"
#include "awcc/units.hpp"
#include "reader_support.hpp"

namespace awcc {

namespace detail {

void reader_fail(const std::filesystem::path& path, std::string_view what, std::string quantity) {
  throw InputError(fmt::format("{}: {}", path.string(), what), std::move(quantity));
}

// To 1e-6 by default: a CSV's time stamps are rounded.
double stated_rate(const std::filesystem::path& path, const ReaderOptions& options, double recorded,
                   const std::string& where, double tolerance) {
  if (!(options.fs > 0.0)) return recorded;
  if (options.override_fs || std::fabs(options.fs - recorded) <= tolerance * recorded) return options.fs;
  reader_fail(path,
              fmt::format("{} records a sampling rate of {} but {} was stated; leave the rate out, or force the "
                          "stated one",
                          where, format_quantity(recorded, Dimension::frequency),
                          format_quantity(options.fs, Dimension::frequency)),
              "override_fs");
}

}  // namespace detail

std::string_view to_string(InputFormat format) {
  switch (format) {
    case InputFormat::automatic: return "auto";
    case InputFormat::sndfile: return "sndfile";
    case InputFormat::uq_dat: return "dat";
    case InputFormat::raw: return "raw";
    case InputFormat::csv: return "csv";
    case InputFormat::tdms: return "tdms";
    case InputFormat::hdf5: return "hdf5";
    case InputFormat::matlab: return "mat";
  }
  return "?";
}

std::string_view to_string(SampleType type) {
  switch (type) {
    case SampleType::int16: return "int16";
    case SampleType::int32: return "int32";
    case SampleType::float32: return "float32";
    case SampleType::float64: return "float64";
  }
  return "?";
}

std::int64_t Recording::read_int16(std::span<std::int16_t>, std::int64_t) {
  throw std::logic_error("read_int16 on a recording without 16-bit integer samples");
}

namespace {

namespace fs = std::filesystem;

using detail::stated_rate;

// `quantity` names the reader setting that fixes the problem (InputError::quantity).
[[noreturn]] void fail(const fs::path& path, std::string_view what, std::string quantity = {}) {
  detail::reader_fail(path, what, std::move(quantity));
}

template <class T>
T load(const char* p, bool swap) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  if (swap) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    std::reverse(b, b + sizeof(T));
    std::memcpy(&v, b, sizeof(T));
  }
  return v;
}

// The data bytes a WAV (RIFF), RF64 or W64 header promises, and where the
// data start; empty for other files or headers that do not say (streaming
// writers leave 0 or 0xFFFFFFFF). libsndfile reads a truncated data chunk
// as if it were whole, so the promise is checked here.
struct DataChunk {
  std::uint64_t offset = 0, declared = 0;
};
std::optional<DataChunk> declared_data(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char head[40] = {};
  in.read(head, 40);
  if (in.gcount() < 40) return std::nullopt;
  auto u32 = [](const char* p) { return load<std::uint32_t>(p, std::endian::native == std::endian::big); };
  auto u64 = [](const char* p) { return load<std::uint64_t>(p, std::endian::native == std::endian::big); };
  const std::string_view magic(head, 4);
  if ((magic == "RIFF" || magic == "RF64") && std::string_view(head + 8, 4) == "WAVE") {
    std::optional<std::uint64_t> ds64_data;
    std::uint64_t pos = 12;
    for (int chunks = 0; chunks < 64; ++chunks) {
      char c[8];
      in.clear();
      in.seekg(static_cast<std::streamoff>(pos));
      in.read(c, 8);
      if (in.gcount() < 8) return std::nullopt;
      const std::string_view id(c, 4);
      const std::uint64_t size = u32(c + 4);
      if (id == "ds64") {
        char d[16];
        in.read(d, 16);
        if (in.gcount() < 16) return std::nullopt;
        ds64_data = u64(d + 8);
      }
      if (id == "data") {
        const std::uint64_t declared = (size == 0xFFFFFFFFu && ds64_data) ? *ds64_data : size;
        if (declared == 0 || declared == 0xFFFFFFFFu) return std::nullopt;
        return DataChunk{pos + 8, declared};
      }
      pos += 8 + size + (size & 1);
    }
    return std::nullopt;
  }
  static const unsigned char riff_guid[16] = {'r', 'i', 'f', 'f', 0x2E, 0x91, 0xCF, 0x11,
                                              0xA5, 0xD6, 0x28, 0xDB, 0x04, 0xC1, 0x00, 0x00};
  static const unsigned char data_guid[16] = {'d', 'a', 't', 'a', 0xF3, 0xAC, 0xD3, 0x11,
                                              0x8C, 0xD1, 0x00, 0xC0, 0x4F, 0x8E, 0xDB, 0x8A};
  if (std::memcmp(head, riff_guid, 16) == 0) {
    std::uint64_t pos = 40;  // riff GUID, size, wave GUID
    for (int chunks = 0; chunks < 64; ++chunks) {
      char c[24];
      in.clear();
      in.seekg(static_cast<std::streamoff>(pos));
      in.read(c, 24);
      if (in.gcount() < 24) return std::nullopt;
      const std::uint64_t size = u64(c + 16);  // includes the 24-byte chunk header
      if (size < 24) return std::nullopt;
      if (std::memcmp(c, data_guid, 16) == 0) return DataChunk{pos + 24, size - 24};
      pos += (size + 7) / 8 * 8;
    }
  }
  return std::nullopt;
}

std::string lower_extension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

void check_finite(const fs::path& path, std::span<const float> values, std::int64_t first_frame, int channels) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) [[unlikely]] {
      fail(path, fmt::format("sample {} of channel {} (frame {}) is {}; the recording is damaged: repair or cut "
                             "it before processing",
                             first_frame + static_cast<std::int64_t>(i) / channels, static_cast<int>(i) % channels,
                             first_frame + static_cast<std::int64_t>(i) / channels,
                             std::isnan(values[i]) ? "NaN" : "infinite"));
    }
  }
}

// ---------------------------------------------------------------------------
// libsndfile containers.

class SndfileRecording final : public Recording {
 public:
  SndfileRecording(const fs::path& path, const ReaderOptions& options) {
    SF_INFO sf{};
    // Owned from here: a refusal below (thrown from the constructor) closes it.
    file_.reset(sf_open(path.c_str(), SFM_READ, &sf));
    if (!file_) {
      fail(path, fmt::format("not a readable audio file (libsndfile: {}); check the file or state its format", 
                             sf_strerror(nullptr)));
    }
    if (sf.channels <= 0 || sf.samplerate <= 0) fail(path, "the audio header has no channels or no sampling rate");
    info_.path = path;
    info_.format = InputFormat::sndfile;
    info_.channels = sf.channels;
    info_.fs = stated_rate(path, options, sf.samplerate, "the file header");
    info_.frames = sf.frames;
    SF_FORMAT_INFO major{};
    major.format = sf.format & SF_FORMAT_TYPEMASK;
    sf_command(file_.get(), SFC_GET_FORMAT_INFO, &major, sizeof(major));
    int bits = 0;
    switch (sf.format & SF_FORMAT_SUBMASK) {
      case SF_FORMAT_PCM_S8: case SF_FORMAT_PCM_U8: bits = 8; break;
      case SF_FORMAT_PCM_16: bits = 16; break;
      case SF_FORMAT_PCM_24: bits = 24; break;
      case SF_FORMAT_PCM_32: bits = 32; break;
      default: bits = 0;
    }
    const int sub = sf.format & SF_FORMAT_SUBMASK;
    floating_ = sub == SF_FORMAT_FLOAT || sub == SF_FORMAT_DOUBLE;
    floating_double_ = sub == SF_FORMAT_DOUBLE;
    int16_ = bits == 16;
    // Companded or compressed samples (u-law, A-law, ADPCM, Vorbis, ...) have
    // no volts: read normalised to full scale 1.
    const bool coded = bits == 0 && !floating_;
    // Values as counts for integer data, as stored for floating data.
    sf_command(file_.get(), SFC_SET_NORM_FLOAT, nullptr, coded ? SF_TRUE : SF_FALSE);
    const double vpc = options.volts_per_count;
    info_.volts_known = !coded && (vpc > 0.0 || floating_);
    if (coded) {
      scale_ = 1.0;
      info_.quantum = 0.0;
    } else if (floating_) {
      scale_ = vpc > 0.0 ? vpc : 1.0;
      info_.quantum = 0.0;
    } else {
      // Unknown scale: full scale is 1 (normalised units).
      scale_ = vpc > 0.0 ? vpc : 1.0 / std::ldexp(1.0, bits - 1);
      info_.quantum = scale_;
    }
    check_complete(path, options, sf, bits);
    info_.description = fmt::format("{} ({}, {})", major.name ? major.name : "audio",
                                    floating_ ? "floating point"
                                              : (coded ? "compressed" : fmt::format("{}-bit integer", bits)),
                                    info_.volts_known ? "volts" : "normalised units");
  }
  // A data chunk shorter than the header promises is refused (or, when
  // allowed, read with a warning naming the promised and present durations).
  void check_complete(const fs::path& path, const ReaderOptions& options, const SF_INFO& sf, int bits) {
    const auto chunk = declared_data(path);
    if (!chunk) return;
    std::error_code ec;
    const std::uint64_t size = fs::file_size(path, ec);
    const std::uint64_t present = size > chunk->offset ? size - chunk->offset : 0;
    if (ec || present >= chunk->declared) return;
    const double frame_bytes = static_cast<double>(sf.channels) * (bits > 0 ? bits / 8 : (floating_double_ ? 8 : 4));
    const double rate = static_cast<double>(sf.samplerate);
    const std::string what = fmt::format(
        "the header promises {:.3f} s of data but the file holds {:.3f} s: it is truncated (a recording still being "
        "written, or a copy cut short)",
        static_cast<double>(chunk->declared) / frame_bytes / rate, static_cast<double>(present) / frame_bytes / rate);
    if (!options.allow_truncated) fail(path, what + "; recover the whole file, or process what is there", "truncated");
    info_.warnings.push_back(what + "; only what is there was processed");
  }


  std::int64_t read(std::span<float> out, std::int64_t max_frames) override {
    const sf_count_t got = sf_readf_float(file_.get(), out.data(), max_frames);
    if (got < 0) fail(info_.path, "read error");
    const auto n = static_cast<std::size_t>(got) * static_cast<std::size_t>(info_.channels);
    if (scale_ != 1.0) {
      const auto s = static_cast<float>(scale_);
      for (std::size_t i = 0; i < n; ++i) out[i] *= s;
    }
    if (floating_) check_finite(info_.path, out.first(n), position_, info_.channels);
    position_ += got;
    if (got == 0 && info_.frames >= 0 && position_ < info_.frames) {
      fail(info_.path, fmt::format("the header announces {} frames but the data ends after {}: the file is truncated",
                                   info_.frames, position_));
    }
    return got;
  }

  void rewind() override {
    sf_seek(file_.get(), 0, SEEK_SET);
    position_ = 0;
  }

  [[nodiscard]] bool has_int16() const override { return int16_; }

  std::int64_t read_int16(std::span<std::int16_t> out, std::int64_t max_frames) override {
    const sf_count_t got = sf_readf_short(file_.get(), out.data(), max_frames);
    if (got < 0) fail(info_.path, "read error");
    position_ += got;
    if (got == 0 && info_.frames >= 0 && position_ < info_.frames) {
      fail(info_.path, fmt::format("the header announces {} frames but the data ends after {}: the file is truncated",
                                   info_.frames, position_));
    }
    return got;
  }

 private:
  std::unique_ptr<SNDFILE, int (*)(SNDFILE*)> file_{nullptr, &sf_close};
  bool floating_ = false;
  bool floating_double_ = false;
  bool int16_ = false;
  double scale_ = 1.0;
  std::int64_t position_ = 0;
};

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
    if (!in_) fail(path, "cannot open for reading");
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
      fail(info_.path, fmt::format("the data ends early, after frame {} of {}: the file is truncated", position_,
                                   info_.frames));
    }
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
      fail(info_.path, fmt::format("the data ends early, after frame {} of {}: the file is truncated", position_,
                                   info_.frames));
    }
    if (swap_) {
      for (std::size_t i = 0; i < count; ++i) {
        const auto u = static_cast<std::uint16_t>(out[i]);
        out[i] = static_cast<std::int16_t>(static_cast<std::uint16_t>((u >> 8) | (u << 8)));
      }
    }
    position_ += n;
    return n;
  }

 private:
  RawLayout layout_;
  std::ifstream in_;
  std::size_t frame_bytes_ = 0;
  bool swap_ = false;
  std::int64_t position_ = 0;
  std::vector<char> bytes_;
};

std::unique_ptr<Recording> open_uq_dat(const fs::path& path, const ReaderOptions& options, std::uintmax_t size) {
  if (size < 8) fail(path, fmt::format("{} bytes is too short for a UQ .dat header (8 bytes)", size));
  std::ifstream in(path, std::ios::binary);
  char header[8];
  in.read(header, 8);
  const auto rows = load<std::int32_t>(header, std::endian::native == std::endian::big);
  const auto channels = load<std::int32_t>(header + 4, std::endian::native == std::endian::big);
  if (rows <= 0 || channels <= 0 || channels > 64) {
    fail(path, fmt::format("the .dat header says {} rows and {} channels, which is not a UQ .dat header; if the file "
                           "is headerless, read it as a raw file with its layout",
                           rows, channels), "format");
  }
  const std::uintmax_t expected = 8 + static_cast<std::uintmax_t>(rows) * static_cast<std::uintmax_t>(channels) * 2;
  if (size < expected) {
    fail(path, fmt::format("the .dat header announces {} rows x {} channels ({} bytes) but the file has {} bytes: it is "
                           "truncated; recover the full recording",
                           rows, channels, expected, size));
  }
  if (size > expected) {
    fail(path, fmt::format("the .dat header announces {} rows x {} channels ({} bytes) but the file has {} bytes: the "
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
  info.format = InputFormat::uq_dat;
  info.description = "UQ LabVIEW .dat (int16, +/-5 V)";
  info.channels = channels;
  info.fs = options.fs;
  if (!(info.fs > 0.0)) {
    fail(path, "a .dat file does not store its sampling rate; state it (e.g. 20 kHz)", "fs");
  }
  info.frames = rows;
  info.quantum = layout.volts_per_count;
  info.volts_known = true;
  return std::make_unique<BinaryRecording>(path, std::move(info), layout);
}

std::unique_ptr<Recording> open_raw(const fs::path& path, const ReaderOptions& options, std::uintmax_t size) {
  const RawLayout& layout = options.raw;
  if (layout.channels <= 0 || layout.channels > 1024) fail(path, fmt::format("raw layout: {} channels is not possible", layout.channels));
  if (layout.header_bytes < 0 || static_cast<std::uintmax_t>(layout.header_bytes) > size) {
    fail(path, fmt::format("raw layout: {} header bytes to skip, but the file has {} bytes", layout.header_bytes, size));
  }
  if (!(options.fs > 0.0)) fail(path, "a raw file does not store its sampling rate; state it (e.g. 500 kHz)", "fs");
  const std::uintmax_t data = size - static_cast<std::uintmax_t>(layout.header_bytes);
  const std::uintmax_t frame = sample_size(layout.sample_type) * static_cast<std::uintmax_t>(layout.channels);
  if (data % frame != 0) {
    fail(path, fmt::format("raw layout: {} data bytes are not a whole number of {}-byte frames ({} channels of {}); "
                           "check the raw layout (channels, sample type, header bytes)",
                           data, frame, layout.channels, to_string(layout.sample_type)), "raw_layout");
  }
  if (data == 0) fail(path, "the raw file holds no samples");
  RecordingInfo info;
  info.path = path;
  info.format = InputFormat::raw;
  info.description = fmt::format("raw {} {}-endian, {} channels", to_string(layout.sample_type),
                                 layout.byte_order == ByteOrder::little ? "little" : "big", layout.channels);
  info.channels = layout.channels;
  info.fs = options.fs;
  info.frames = static_cast<std::int64_t>(data / frame);
  const bool integer = layout.sample_type == SampleType::int16 || layout.sample_type == SampleType::int32;
  info.quantum = integer ? layout.volts_per_count : 0.0;
  info.volts_known = true;
  return std::make_unique<BinaryRecording>(path, std::move(info), layout);
}

// ---------------------------------------------------------------------------
// CSV / TSV.

std::vector<std::string_view> split(std::string_view line, char delimiter) {
  std::vector<std::string_view> cells;
  if (delimiter != ' ' && line.find('"') != std::string_view::npos) {
    // Quoted cells ("0,001";"1,5"): split outside the quotes; trim() drops the quotes.
    bool quoted = false;
    std::size_t start = 0;
    for (std::size_t i = 0; i < line.size(); ++i) {
      if (line[i] == '"') quoted = !quoted;
      else if (line[i] == delimiter && !quoted) {
        cells.push_back(line.substr(start, i - start));
        start = i + 1;
      }
    }
    cells.push_back(line.substr(start));
    return cells;
  }
  if (delimiter == ' ') {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i >= line.size()) break;
      std::size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
      cells.push_back(line.substr(i, j - i));
      i = j;
    }
    return cells;
  }
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = line.find(delimiter, start);
    cells.push_back(line.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return cells;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '"')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '"')) s.remove_suffix(1);
  return s;
}

bool parse_number(std::string_view cell, double& value) {
  cell = trim(cell);
  if (cell.empty()) return false;
  const char* first = cell.data();
  if (*first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, cell.data() + cell.size(), value);
  return ec == std::errc{} && ptr == cell.data() + cell.size();
}

// Lines longer than this are not rows of a column file; refusing them keeps
// memory bounded whatever the file holds.
constexpr std::size_t kMaxCsvLine = 1 << 20;

// std::getline, but refusing lines longer than kMaxCsvLine.
bool bounded_getline(std::istream& in, std::string& line, const fs::path& path, std::int64_t number) {
  line.clear();
  for (;;) {
    const int c = in.get();
    if (c == std::char_traits<char>::eof()) return !line.empty();  // a last line without newline counts
    if (c == '\n') return true;
    line.push_back(static_cast<char>(c));
    if (line.size() > kMaxCsvLine) {
      fail(path, fmt::format("line {} is longer than {} bytes: not a column file (or a damaged one)", number,
                             kMaxCsvLine));
    }
  }
}

// Column files as labs write them: comma, tab, semicolon or blank
// separated; a decimal point or (European locales) a decimal comma; an
// optional header row; LabVIEW .lvm text (header blocks ending in
// ***End_of_Header***, X_Value as time, Delta_X as the sample interval, an
// empty Comment column). Separator and decimal mark come from the content
// (or the .lvm header); the time column from its name (time, t, zeit, temps,
// tiempo, X_Value, with a unit in brackets) or from its values (strictly
// increasing with a constant step, when the file has at least three columns).
class CsvRecording final : public Recording {
 public:
  CsvRecording(const fs::path& path, const ReaderOptions& options) : in_(path, std::ios::binary) {
    if (!in_) fail(path, "cannot open for reading");
    info_.path = path;
    info_.format = InputFormat::csv;
    std::string line;
    std::int64_t number = 0;
    // LabVIEW .lvm: header blocks up to the last ***End_of_Header*** before the data.
    std::optional<double> lvm_delta;
    char lvm_separator = 0, lvm_decimal = 0;
    bool lvm = false;
    int markers = 0;
    std::streampos body = 0;
    std::int64_t body_line = 0;
    {
      std::streampos at = in_.tellg();
      if (bounded_getline(in_, line, path, 1) && trim(line).starts_with("LabVIEW Measurement")) lvm = true;
      in_.clear();
      in_.seekg(at);
      if (lvm) {
        while (bounded_getline(in_, line, path, ++number)) {
          const auto cells = split(line, '\t');
          const auto key = cells.empty() ? std::string_view{} : trim(cells[0]);
          const auto value = cells.size() > 1 ? trim(cells[1]) : std::string_view{};
          if (key == "Separator") lvm_separator = value == "Comma" ? ',' : (value == "Tab" ? '\t' : 0);
          if (key == "Decimal_Separator" && !value.empty()) lvm_decimal = value[0];
          if (key == "Delta_X") {
            double d;
            std::string v(value);
            std::replace(v.begin(), v.end(), ',', '.');
            if (parse_number(v, d) && d > 0.0) lvm_delta = d;
          }
          if (trim(line).starts_with("***End_of_Header***")) {
            body = in_.tellg();
            body_line = number;
            // The file header, then the first segment's: its data follow.
            // Later segments (their headers inside the data) are refused
            // by read() as rows that are not numbers.
            if (++markers == 2) break;
          }
        }
        if (body_line == 0) fail(path, "a LabVIEW measurement file without ***End_of_Header***: not a recording", "not_a_recording");
        in_.clear();
        in_.seekg(body);
        number = body_line;
      }
    }
    // The first rows: separator, decimal mark, header, columns.
    std::vector<std::string> rows;
    std::vector<std::int64_t> row_lines;
    std::vector<std::streampos> row_starts;
    while (rows.size() < 50) {
      const std::streampos at = in_.tellg();
      if (!bounded_getline(in_, line, path, ++number)) break;
      if (trim(line).empty()) continue;
      rows.push_back(line);
      row_lines.push_back(number);
      row_starts.push_back(at);
    }
    if (rows.empty()) fail(path, "the file holds no rows", "not_a_recording");
    auto in_every = [&](char c) {
      return std::all_of(rows.begin(), rows.end(), [c](const std::string& r) { return r.find(c) != std::string::npos; });
    };
    delimiter_ = options.csv.delimiter ? options.csv.delimiter : lvm_separator;
    if (!delimiter_) {
      if (in_every('\t')) delimiter_ = '\t';
      else if (in_every(';')) delimiter_ = ';';
      else if (in_every(',')) delimiter_ = ',';
      else delimiter_ = ' ';
    }
    decimal_ = lvm_decimal ? lvm_decimal : '.';
    if (!lvm_decimal && delimiter_ != ',') {
      // A decimal comma: digits on both sides of a comma in a cell, and no decimal point.
      bool comma = false, point = false;
      for (std::size_t r = rows.size() > 1 ? 1 : 0; r < rows.size(); ++r) {
        for (auto cell : split(rows[r], delimiter_)) {
          cell = trim(cell);
          for (std::size_t k = 1; k + 1 < cell.size(); ++k) {
            const bool digits = std::isdigit(static_cast<unsigned char>(cell[k - 1])) &&
                                std::isdigit(static_cast<unsigned char>(cell[k + 1]));
            if (cell[k] == ',' && digits) comma = true;
            if (cell[k] == '.' && digits) point = true;
          }
        }
      }
      if (comma && !point) decimal_ = ',';
    }
    const auto first = split(rows[0], delimiter_);
    bool all_numbers = true;
    double v;
    for (auto c : first) all_numbers = all_numbers && (trim(c).empty() || number_of(c, v));
    const bool header = options.csv.header.value_or(!all_numbers);
    columns_ = static_cast<int>(first.size());
    const std::size_t first_data = header ? 1 : 0;
    if (first_data >= rows.size()) fail(path, "the file holds a header row and no data: not a recording", "not_a_recording");
    {
      const auto cells = split(rows[first_data], delimiter_);
      std::size_t numeric = 0;
      for (auto c : cells) numeric += number_of(c, v) ? 1 : 0;
      if (numeric == 0) {
        fail(path, fmt::format("line {} holds no number: not a column file of samples", row_lines[first_data]),
             "not_a_recording");
      }
    }
    std::vector<std::string> names(static_cast<std::size_t>(columns_));
    for (int c = 0; c < columns_; ++c) {
      names[static_cast<std::size_t>(c)] =
          header ? std::string(trim(first[static_cast<std::size_t>(c)])) : fmt::format("column {}", c);
    }
    // Columns that hold no samples: LabVIEW's Comment, or one left empty in every row (a trailing separator).
    std::vector<bool> skip(static_cast<std::size_t>(columns_), false);
    for (int c = 0; c < columns_; ++c) {
      std::string lower = names[static_cast<std::size_t>(c)];
      std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
      bool empty = true;
      for (std::size_t r = first_data; r < rows.size(); ++r) {
        const auto cells = split(rows[r], delimiter_);
        if (static_cast<int>(cells.size()) > c && !trim(cells[static_cast<std::size_t>(c)]).empty()) empty = false;
      }
      skip[static_cast<std::size_t>(c)] = lower == "comment" || empty;
    }
    time_column_ = options.csv.time_column;
    if (time_column_ >= columns_) {
      fail(path, fmt::format("time column {} does not exist: the file has {} columns", time_column_, columns_), "time_column");
    }
    if (time_column_ == -2) {
      time_column_ = -1;
      for (int c = 0; header && c < columns_ && time_column_ < 0; ++c) {
        if (!skip[static_cast<std::size_t>(c)] && is_time_name(names[static_cast<std::size_t>(c)])) time_column_ = c;
      }
      const int usable = static_cast<int>(std::count(skip.begin(), skip.end(), false));
      for (int c = 0; usable >= 3 && c < columns_ && time_column_ < 0; ++c) {
        if (!skip[static_cast<std::size_t>(c)] && evenly_increasing(rows, first_data, c)) time_column_ = c;
      }
    }
    for (int c = 0; c < columns_; ++c) {
      if (c == time_column_ || skip[static_cast<std::size_t>(c)]) continue;
      // LabVIEW's one X column per channel: the other time columns are not data.
      if (time_column_ >= 0 && header && is_time_name(names[static_cast<std::size_t>(c)])) continue;
      data_columns_.push_back(c);
      info_.channel_names.push_back(names[static_cast<std::size_t>(c)]);
    }
    info_.channels = static_cast<int>(data_columns_.size());
    if (info_.channels <= 0) fail(path, "the file has no data column besides its time column", "not_a_recording");
    data_start_ = row_starts[first_data];
    first_line_ = row_lines[first_data] - 1;
    in_.clear();
    in_.seekg(data_start_);
    line_ = first_line_;
    if (lvm_delta) {
      info_.fs = stated_rate(path, options, 1.0 / *lvm_delta, "its Delta_X");
    } else if (time_column_ >= 0) {
      const double unit = time_unit(header ? names[static_cast<std::size_t>(time_column_)] : std::string());
      // Time stamps are printed rounded: the rate from them agrees with a
      // stated one to 0.1 %, not to the last digit.
      info_.fs = stated_rate(path, options, fs_from_time_column() / unit,
                             fmt::format("its time column '{}'", names[static_cast<std::size_t>(time_column_)]), 1e-3);
    } else if (options.fs > 0.0) {
      info_.fs = options.fs;
    } else {
      fail(path, "the file has no time column; state the sampling rate, or name the time column", "fs");
    }
    info_.volts_known = true;
    info_.quantum = 0.0;
    std::string tips;
    for (const auto& n : info_.channel_names) tips += (tips.empty() ? "'" : ", '") + n + "'";
    info_.description = fmt::format(
        "{} ({} columns, {} separated, decimal {}{}{}; channels {})", lvm ? "LabVIEW text" : "CSV", columns_,
        delimiter_ == '\t' ? "tab" : (delimiter_ == ' ' ? "blank" : fmt::format("'{}'", delimiter_)),
        decimal_ == ',' ? "comma" : "point", header ? ", header row" : "",
        time_column_ >= 0 ? fmt::format(", time in '{}'", names[static_cast<std::size_t>(time_column_)]) : "", tips);
    rewind();
  }

  std::int64_t read(std::span<float> out, std::int64_t max_frames) override {
    std::int64_t n = 0;
    std::string line;
    while (n < max_frames && bounded_getline(in_, line, info_.path, line_ + 1)) {
      ++line_;
      if (trim(line).empty()) continue;
      const auto cells = split(line, delimiter_);
      if (static_cast<int>(cells.size()) != columns_) {
        fail(info_.path, fmt::format("line {} has {} cells where the first row has {}; fix or remove the line", line_,
                                     cells.size(), columns_));
      }
      int k = 0;
      for (int c : data_columns_) {
        double v;
        if (!number_of(cells[static_cast<std::size_t>(c)], v)) {
          fail(info_.path, fmt::format("line {}, column {}: '{}' is not a number; fix the cell or remove the line",
                                       line_, c + 1, trim(cells[static_cast<std::size_t>(c)])));
        }
        if (!std::isfinite(v)) {
          fail(info_.path, fmt::format("line {}, column {}: the value is not finite; the recording is damaged", line_, c + 1));
        }
        // Samples are 32-bit floats: a larger magnitude would become infinite.
        if (std::fabs(v) > static_cast<double>(std::numeric_limits<float>::max())) {
          fail(info_.path, fmt::format("line {}, column {}: {:g} lies beyond the range of a sample (+/- 3.4e38); the "
                                       "recording is damaged: fix the cell or remove the line", line_, c + 1, v));
        }
        out[static_cast<std::size_t>(n * info_.channels + k++)] = static_cast<float>(v);
      }
      ++n;
    }
    return n;
  }

  void rewind() override {
    in_.clear();
    in_.seekg(data_start_);
    line_ = first_line_;
  }

 private:
  // A number in the file's decimal convention.
  [[nodiscard]] bool number_of(std::string_view cell, double& value) const {
    if (decimal_ == '.') return parse_number(cell, value);
    std::string c(trim(cell));
    std::replace(c.begin(), c.end(), ',', '.');
    return parse_number(c, value);
  }

  // The rounding step of printed stamps: the least gap between distinct step
  // values (steps of 3 and 4 us at 300 kHz printed to 1 us give 1 us); 0
  // when every step is the same.
  static double resolution(std::vector<double> steps) {
    std::sort(steps.begin(), steps.end());
    double r = 0.0;
    for (std::size_t i = 1; i < steps.size(); ++i) {
      const double d = steps[i] - steps[i - 1];
      if (d > 1e-9 * std::fabs(steps[i]) && (r == 0.0 || d < r)) r = d;
    }
    return r;
  }

  // Seconds per unit of a time column named with a unit in brackets
  // ("Time [ms]", "t (us)"); 1 without one.
  double time_unit(const std::string& name) const {
    for (auto [open, close] : {std::pair{'[', ']'}, std::pair{'(', ')'}}) {
      const auto a = name.find(open), b = name.find(close);
      if (a == std::string::npos || b == std::string::npos || b <= a + 1) continue;
      try {
        return parse_quantity("1" + name.substr(a + 1, b - a - 1), Dimension::time);
      } catch (const std::invalid_argument&) {
        fail(info_.path, fmt::format("the time column '{}' has a unit that is not a time", name), "time_column");
      }
    }
    return 1.0;
  }

  static bool is_time_name(std::string name) {
    // Without a unit in brackets, lower case: time, t, zeit, temps, tiempo, x_value, ...
    for (const char* open : {"[", "("}) {
      const auto at = name.find(open);
      if (at != std::string::npos && at > 0) name.resize(at);
    }
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
    name = std::string(trim(name));
    for (const char* known : {"time", "t", "zeit", "temps", "tiempo", "x_value", "time_s", "seconds", "s", "sec"}) {
      if (name == known) return true;
    }
    return false;
  }

  // Strictly increasing with a constant step (to 1e-6 of it) over the sampled rows.
  [[nodiscard]] bool evenly_increasing(const std::vector<std::string>& rows, std::size_t first, int column) const {
    std::vector<double> t;
    for (std::size_t r = first; r < rows.size(); ++r) {
      const auto cells = split(rows[r], delimiter_);
      double v;
      if (static_cast<int>(cells.size()) <= column || !number_of(cells[static_cast<std::size_t>(column)], v)) return false;
      t.push_back(v);
    }
    if (t.size() < 3) return false;
    const double step = t[1] - t[0];
    if (!(step > 0.0)) return false;
    for (std::size_t i = 1; i < t.size(); ++i) {
      if (std::fabs((t[i] - t[i - 1]) - step) > 1e-6 * std::fabs(step) + 1e-12 * std::fabs(t[i])) return false;
    }
    return true;
  }

  double fs_from_time_column() {
    // The sampling interval from the first rows' time stamps (median step).
    std::vector<double> times;
    std::string line;
    std::int64_t number = line_;
    while (times.size() < 2001 && bounded_getline(in_, line, info_.path, ++number)) {
      if (trim(line).empty()) continue;
      const auto cells = split(line, delimiter_);
      double t;
      if (static_cast<int>(cells.size()) != columns_ || !number_of(cells[static_cast<std::size_t>(time_column_)], t)) break;
      times.push_back(t);
    }
    if (times.size() < 2) fail(info_.path, "too few rows to take the sampling rate from the time column; state the sampling rate", "fs");
    std::vector<double> steps;
    for (std::size_t i = 1; i < times.size(); ++i) steps.push_back(times[i] - times[i - 1]);
    // The mean step (last minus first over the steps) is as exact as the
    // stamps' rounding allows; the median guards against a column that is
    // not a clock (steps that vary by more than 1 %).
    const double dt = (times.back() - times.front()) / static_cast<double>(times.size() - 1);
    const double typical = median(steps);
    if (!(dt > 0.0) || !(typical > 0.0)) {
      fail(info_.path, "the time column does not increase; state the sampling rate or fix the column", "time_column");
    }
    if (std::fabs(typical / dt - 1.0) > 0.01 && std::fabs(typical - dt) > 1.001 * resolution(steps)) {
      fail(info_.path, fmt::format("the time column's steps are uneven ({:.6g} typical, {:.6g} on average): not a "
                                   "clock of evenly spaced samples; name the time column or state the sampling rate",
                                   typical, dt),
           "time_column");
    }
    return 1.0 / dt;
  }

  std::ifstream in_;
  char delimiter_ = ',';
  char decimal_ = '.';
  int columns_ = 0;
  int time_column_ = -1;
  std::vector<int> data_columns_;
  std::streampos data_start_ = 0;
  std::int64_t line_ = 0, first_line_ = 0;
};

bool looks_like_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char buffer[512];
  in.read(buffer, sizeof(buffer));
  const auto n = in.gcount();
  if (n <= 0) return false;
  for (std::streamsize i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(buffer[i]);
    if (c == 0 || (c < 32 && c != '\n' && c != '\r' && c != '\t')) return false;
  }
  return true;
}

bool audio_magic(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char m[4] = {0, 0, 0, 0};
  in.read(m, 4);
  const std::string_view s(m, 4);
  return s == "RIFF" || s == "RIFX" || s == "RF64" || s == "fLaC" || s == "FORM" || s == "riff" || s == "OggS" ||
         s == "caff" || s == ".snd";
}

}  // namespace

namespace {

// Samples already in memory: read() copies the next frames out.
template <class Sample>
class MemoryRecording final : public Recording {
 public:
  MemoryRecording(std::vector<Sample> samples, int channels, double fs, double quantum, bool volts_known,
                  std::string name)
      : samples_(std::move(samples)) {
    const fs::path path(name);
    if (channels < 1) fail(path, "no channel: give at least one array", "channels");
    const auto c = static_cast<std::size_t>(channels);
    if (samples_.size() % c != 0) {
      fail(path, fmt::format("{} samples are not whole frames of {} channels; give arrays of one length",
                             samples_.size(), channels), "channels");
    }
    if (samples_.empty()) fail(path, "no sample: the arrays are empty");
    if (!(fs > 0.0) || !std::isfinite(fs)) fail(path, fmt::format("sampling rate {} Hz: give a positive rate", fs), "fs");
    if constexpr (std::is_floating_point_v<Sample>) {
      for (std::size_t i = 0; i < samples_.size(); ++i) {
        if (!std::isfinite(samples_[i])) {
          fail(path, fmt::format("sample {} of channel {} is {}; remove or fill non-finite values first", i / c, i % c,
                                 samples_[i]), "volts");
        }
      }
    }
    info_.path = path;
    info_.format = InputFormat::automatic;
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
    fail(name, fmt::format("{} V per count: give a positive scale", quantum), "volts_per_count");
  }
  return std::make_unique<MemoryRecording<std::int16_t>>(std::move(interleaved), channels, fs, quantum, volts_known,
                                                         std::move(name));
}

namespace detail {
// The writer in libsynth takes the same lock (libcore owns it).
std::mutex& hdf5_library_mutex() { return pdpsim::hdf5_mutex(); }
}  // namespace detail

std::unique_ptr<Recording> open_recording(const fs::path& path, const ReaderOptions& options) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(path, "no such file");
  if (fs::is_directory(path, ec)) fail(path, "is a folder, not a recording", "not_a_recording");
  const auto size = fs::file_size(path, ec);
  if (ec) fail(path, fmt::format("cannot read: {}", ec.message()));
  if (size == 0) fail(path, "the file is empty");
  InputFormat format = options.format;
  const std::string ext = lower_extension(path);
  if (format == InputFormat::automatic) {
    static const std::string_view audio_ext[] = {".wav", ".w64", ".rf64", ".flac", ".aif", ".aiff", ".aifc",
                                                 ".au",  ".snd", ".caf",  ".ogg"};
    static const std::string_view not_recordings[] = {".md", ".json", ".html", ".htm", ".pdf", ".png", ".jpg",
                                                      ".svg", ".toml", ".py", ".sh", ".qrf", ".yaml", ".yml"};
    if (std::find(std::begin(not_recordings), std::end(not_recordings), ext) != std::end(not_recordings)) {
      fail(path, fmt::format("a {} file is not a recording", ext), "not_a_recording");
    }
    if (ext == ".dat") format = InputFormat::uq_dat;
    else if (ext == ".tdms" || detail::tdms_magic(path)) format = InputFormat::tdms;
    // A v7.3 MAT-file is an HDF5 file behind a MATLAB header: ask the header first.
    else if (ext == ".mat" || detail::matlab_magic(path)) format = InputFormat::matlab;
    else if (ext == ".h5" || ext == ".hdf5" || ext == ".hdf" || ext == ".he5" || detail::hdf5_magic(path))
      format = InputFormat::hdf5;
    else if (audio_magic(path) || std::find(std::begin(audio_ext), std::end(audio_ext), ext) != std::end(audio_ext))
      format = InputFormat::sndfile;
    else if (ext == ".raw" || ext == ".bin" || ext == ".pcm") format = InputFormat::raw;
    else if (ext == ".csv" || ext == ".tsv" || ext == ".txt" || ext == ".lvm" || looks_like_text(path))
      format = InputFormat::csv;
    else fail(path, "cannot tell the recording's format from its name or content; state the format (sndfile, dat, raw, csv, tdms, hdf5 or mat)", "format");
  }
  switch (format) {
    case InputFormat::sndfile: return std::make_unique<SndfileRecording>(path, options);
    case InputFormat::uq_dat: return open_uq_dat(path, options, size);
    case InputFormat::raw: return open_raw(path, options, size);
    case InputFormat::csv: return std::make_unique<CsvRecording>(path, options);
    case InputFormat::tdms: return detail::open_tdms(path, options);
    case InputFormat::hdf5: return detail::open_hdf5(path, options);
    case InputFormat::matlab: return detail::open_matlab(path, options);
    case InputFormat::automatic: break;
  }
  fail(path, "unknown format");
}

}  // namespace awcc
