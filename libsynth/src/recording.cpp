#include "synth/recording.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <sndfile.h>
#include <stdexcept>

#include "awcc/atomic_output.hpp"
#include "awcc/errors.hpp"
#include "awcc/units.hpp"

namespace synth {

std::string_view to_string(FileFormat format) {
  switch (format) {
    case FileFormat::flac: return "flac";
    case FileFormat::wav: return "wav";
    case FileFormat::w64: return "w64";
    case FileFormat::rf64: return "rf64";
    case FileFormat::hdf5: return "h5";
  }
  return "?";
}

std::string_view to_string(SignalKind signal) { return signal == SignalKind::binary ? "binary" : "voltage"; }

std::optional<FileFormat> format_from_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".flac") return FileFormat::flac;
  if (ext == ".wav") return FileFormat::wav;
  if (ext == ".w64") return FileFormat::w64;
  if (ext == ".rf64") return FileFormat::rf64;
  if (ext == ".h5" || ext == ".hdf5") return FileFormat::hdf5;
  return std::nullopt;
}

namespace detail {
// hdf5_recording.cpp: writes `file` (already the temporary name); messages name `shown`.
void write_hdf5(const std::filesystem::path& file, const std::filesystem::path& shown, const Scene& scene,
                std::span<const awcc::AirIntervals> signals, const RecordingOptions& options);
}  // namespace detail

namespace {

int sf_major(FileFormat format) {
  switch (format) {
    case FileFormat::flac: return SF_FORMAT_FLAC;
    case FileFormat::wav: return SF_FORMAT_WAV;
    case FileFormat::w64: return SF_FORMAT_W64;
    case FileFormat::rf64: return SF_FORMAT_RF64;
    case FileFormat::hdf5: break;
  }
  return SF_FORMAT_WAV;
}

}  // namespace

std::string check_recordable(const Scene& scene, std::size_t channels, FileFormat format) {
  // HDF5 stores the rate as a float64 time base and any number of tips.
  if (format == FileFormat::hdf5) return {};
  if (scene.fs != std::floor(scene.fs) || scene.fs > 2.0e9) {
    return fmt::format("fs = {} Hz: audio containers store a whole number of hertz up to 2 GHz; choose such an fs",
                       scene.fs);
  }
  if (format == FileFormat::flac) {
    if (channels > 8) return fmt::format("FLAC holds at most 8 channels, the probe has {} tips; write .w64 or .rf64", channels);
    if (scene.fs > 655350.0)
      return fmt::format("FLAC stores sampling rates up to 655350 Hz, fs is {}; write .w64 or .rf64 instead",
                         awcc::format_quantity(scene.fs, awcc::Dimension::frequency));
  }
  const double bytes = static_cast<double>(scene.sample_count()) * static_cast<double>(channels) * 2.0;
  if (format == FileFormat::wav && bytes > 4.0e9)
    return fmt::format("WAV files end at 4 GB and this recording needs {:.1f} GB; write .w64 or .rf64", bytes / 1e9);
  return {};
}

VoltageRenderer::VoltageRenderer(const Scene& scene, std::size_t tips)
    : rng_(scene.seed, Stream::noise),
      water_(scene.voltage_water),
      air_(scene.voltage_air),
      decay_(scene.voltage_time_constant > 0.0 ? std::exp(-1.0 / (scene.fs * scene.voltage_time_constant)) : 0.0),
      noise_(scene.voltage_noise),
      full_scale_(scene.voltage_full_scale),
      state_(tips, 0.0) {}

void VoltageRenderer::render(const std::vector<std::span<const std::uint8_t>>& air,
                             std::span<std::int16_t> interleaved) {
  const std::size_t tips = state_.size();
  const std::size_t frames = tips ? interleaved.size() / tips : 0;
  if (!started_ && frames > 0) {
    for (std::size_t j = 0; j < tips; ++j) state_[j] = air[j][0] ? air_ : water_;
    started_ = true;
  }
  const double counts_per_volt = 32768.0 / full_scale_;
  for (std::size_t i = 0; i < frames; ++i) {
    for (std::size_t j = 0; j < tips; ++j) {
      const double level = air[j][i] ? air_ : water_;
      state_[j] = level + (state_[j] - level) * decay_;
      const double v = state_[j] + noise_ * rng_.normal();
      const double counts = std::clamp(std::nearbyint(v * counts_per_volt), -32768.0, 32767.0);
      interleaved[i * tips + j] = static_cast<std::int16_t>(counts);
    }
  }
}

void write_recording(const std::filesystem::path& path, const Scene& scene,
                     std::span<const awcc::AirIntervals> signals, const RecordingOptions& options) {
  const std::size_t channels = signals.size();
  if (channels == 0) throw awcc::OptionError(fmt::format("{}: no signal to write; give one per tip", path.string()));
  if (const auto why = check_recordable(scene, channels, options.format); !why.empty()) {
    throw awcc::OptionError(fmt::format("{}: {}", path.string(), why));
  }
  if (options.format == FileFormat::hdf5) {
    awcc::write_atomically(path, [&](const std::filesystem::path& temporary) {
      detail::write_hdf5(temporary, path, scene, signals, options);
    });
    return;
  }
  const std::int64_t frames = signals.front().sample_count;
  awcc::write_atomically(path, [&](const std::filesystem::path& temporary) {
    SF_INFO info{};
    info.samplerate = static_cast<int>(scene.fs);
    info.channels = static_cast<int>(channels);
    info.format = sf_major(options.format) | SF_FORMAT_PCM_16;
    SNDFILE* file = sf_open(temporary.c_str(), SFM_WRITE, &info);
    if (!file) {
      throw awcc::OutputError(fmt::format("{}: cannot create the {} file: {}", path.string(), to_string(options.format),
                                           sf_strerror(nullptr)));
    }
    struct Closer {
      SNDFILE* f;
      ~Closer() { if (f) sf_close(f); }
    } closer{file};
    if (options.format == FileFormat::flac) {
      double level = std::clamp(options.flac_compression, 0.0, 1.0);
      sf_command(file, SFC_SET_COMPRESSION_LEVEL, &level, sizeof(level));
    }
    const std::int64_t block = std::max<std::int64_t>(1, options.block_frames);
    std::vector<std::vector<std::uint8_t>> air(channels, std::vector<std::uint8_t>(static_cast<std::size_t>(block)));
    std::vector<std::int16_t> interleaved(static_cast<std::size_t>(block) * channels);
    std::optional<VoltageRenderer> renderer;
    if (options.signal == SignalKind::voltage) renderer.emplace(scene, channels);
    for (std::int64_t first = 0; first < frames; first += block) {
      const auto n = static_cast<std::size_t>(std::min(block, frames - first));
      std::vector<std::span<const std::uint8_t>> views;
      for (std::size_t j = 0; j < channels; ++j) {
        signals[j].render(first, std::span<std::uint8_t>(air[j].data(), n));
        views.emplace_back(air[j].data(), n);
      }
      std::span<std::int16_t> out(interleaved.data(), n * channels);
      if (renderer) {
        renderer->render(views, out);
      } else {
        for (std::size_t i = 0; i < n; ++i)
          for (std::size_t j = 0; j < channels; ++j) out[i * channels + j] = static_cast<std::int16_t>(air[j][i]);
      }
      if (sf_writef_short(file, out.data(), static_cast<sf_count_t>(n)) != static_cast<sf_count_t>(n)) {
        throw awcc::OutputError(fmt::format("{}: writing failed after {} frames: {}", path.string(), first,
                                             sf_strerror(file)));
      }
      if (options.progress) options.progress(static_cast<double>(first + static_cast<std::int64_t>(n)) / static_cast<double>(frames));
    }
    closer.f = nullptr;
    if (sf_close(file) != 0) throw awcc::OutputError(fmt::format("{}: closing the file failed", path.string()));
  });
}

std::vector<std::int16_t> read_recording_int16(const std::filesystem::path& path, int& channels, double& fs) {
  SF_INFO info{};
  SNDFILE* file = sf_open(path.c_str(), SFM_READ, &info);
  if (!file) throw awcc::InputError(fmt::format("{}: cannot open: {}; check the path", path.string(), sf_strerror(nullptr)));
  channels = info.channels;
  fs = info.samplerate;
  std::vector<std::int16_t> data(static_cast<std::size_t>(info.frames) * static_cast<std::size_t>(info.channels));
  const sf_count_t got = sf_readf_short(file, data.data(), info.frames);
  sf_close(file);
  data.resize(static_cast<std::size_t>(got) * static_cast<std::size_t>(channels));
  return data;
}

}  // namespace synth
