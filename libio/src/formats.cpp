// The format registry (awcc/recording.hpp): one row per format, from which
// open_recording's detection, the names `format` takes and the messages that
// list them are all derived. A new format is its reader's file plus one row
// here (its entry points declared in reader_support.hpp).
#include <algorithm>
#include <array>
#include <fmt/format.h>

#include "reader_support.hpp"

namespace awcc {

namespace {

namespace fs = std::filesystem;

using detail::reader_fail;

struct Format {
  std::string_view name;  ///< as ReaderOptions::format states it, RecordingInfo::format reports it
  /// Detection tries the formats by rank, lowest first; a format claims a
  /// file by its extension or its magic. The order matters: a .dat is UQ's
  /// whatever its bytes; a v7.3 MAT-file is an HDF5 file behind a MATLAB
  /// header (mat before hdf5); nearly any short file is text (csv last).
  int rank;
  std::string_view extensions;     ///< lower case, with the dot, separated by blanks
  bool (*magic)(const fs::path&);  ///< its first bytes; nullptr: none tells
  std::unique_ptr<Recording> (*open)(const fs::path&, const ReaderOptions&);
};

// In the order the formats are listed to users (help, messages).
constexpr std::array kFormats{
    Format{"sndfile", 4, ".wav .w64 .rf64 .flac .aif .aiff .aifc .au .snd .caf .ogg",
           &detail::audio_magic, &detail::open_sndfile},
    Format{"dat", 0, ".dat", nullptr, &detail::open_uq_dat},
    Format{"raw", 5, ".raw .bin .pcm", nullptr, &detail::open_raw},
    Format{"csv", 6, ".csv .tsv .txt .lvm", &detail::looks_like_text, &detail::open_csv},
    Format{"tdms", 1, ".tdms", &detail::tdms_magic, &detail::open_tdms},
    Format{"hdf5", 3, ".h5 .hdf5 .hdf .he5", &detail::hdf5_magic, &detail::open_hdf5},
    Format{"mat", 2, ".mat", &detail::matlab_magic, &detail::open_matlab},
};

// Files a glob catches beside recordings: refused by name, before any reader guesses.
constexpr std::string_view kNotRecordings[] = {".md",  ".json", ".html", ".htm", ".pdf", ".png", ".jpg",
                                               ".svg", ".toml", ".py",   ".sh",  ".qrf", ".yaml", ".yml"};

std::string lower_extension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

bool has_extension(std::string_view list, std::string_view ext) {
  for (std::size_t at = 0; at < list.size();) {
    const auto end = std::min(list.find(' ', at), list.size());
    if (list.substr(at, end - at) == ext) return true;
    at = end + 1;
  }
  return false;
}

const Format* find_format(std::string_view name) {
  for (const auto& f : kFormats) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

// The format by extension or content, trying the formats by rank.
const Format& detect(const fs::path& path) {
  const std::string ext = lower_extension(path);
  if (std::find(std::begin(kNotRecordings), std::end(kNotRecordings), ext) != std::end(kNotRecordings)) {
    reader_fail(path, fmt::format("a {} file is not a recording", ext), "not_a_recording");
  }
  std::array<const Format*, kFormats.size()> order{};
  std::transform(kFormats.begin(), kFormats.end(), order.begin(), [](const Format& f) { return &f; });
  std::sort(order.begin(), order.end(), [](const Format* a, const Format* b) { return a->rank < b->rank; });
  for (const Format* f : order) {
    if (!ext.empty() && has_extension(f->extensions, ext)) return *f;
    if (f->magic && f->magic(path)) return *f;
  }
  std::string names;
  for (std::size_t i = 0; i < kFormats.size(); ++i) {
    names += (i == 0 ? "" : (i + 1 == kFormats.size() ? " or " : ", ")) + std::string(kFormats[i].name);
  }
  reader_fail(path,
              fmt::format("cannot tell the recording's format from its name or content; state the format ({})", names),
              "format");
}

}  // namespace

std::span<const std::string_view> input_formats() {
  static const auto names = [] {
    std::array<std::string_view, kFormats.size()> out{};
    std::transform(kFormats.begin(), kFormats.end(), out.begin(), [](const Format& f) { return f.name; });
    return out;
  }();
  return names;
}

std::unique_ptr<Recording> open_recording(const fs::path& path, const ReaderOptions& options) {
  std::error_code ec;
  if (!fs::exists(path, ec)) reader_fail(path, "no such file");
  if (fs::is_directory(path, ec)) reader_fail(path, "is a folder, not a recording", "not_a_recording");
  const auto size = fs::file_size(path, ec);
  if (ec) reader_fail(path, fmt::format("cannot read: {}", ec.message()));
  if (size == 0) reader_fail(path, "the file is empty");
  const Format* format = options.format == kAutomaticFormat ? &detect(path) : find_format(options.format);
  if (!format) {
    std::string names(kAutomaticFormat);
    for (const auto& f : kFormats) names += ", " + std::string(f.name);
    reader_fail(path, fmt::format("'{}' is not a recording format; state one of {}", options.format, names),
                "format");
  }
  auto recording = format->open(path, options);
  recording->info_.format = format->name;
  return recording;
}

}  // namespace awcc
