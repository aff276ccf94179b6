#pragma once
// Recordings of the synthetic probe: one multi-channel file per recording,
// one channel per tip in tip order: an audio container through libsndfile
// (16-bit integer samples), or pdp-sim's HDF5 layout (awcc/pdpsim_layout.hpp:
// `signal` samples x tips, uint8 0/1 for binary signals as pdp-sim writes
// them, int16 counts with a `volts_per_count` attribute for raw voltages, a
// form pdp-sim itself does not produce; `time` in seconds; `sensor_id` and
// `fs` attributes on `signal`).
//
// Binary signals hold 0 (water) and 1 (air) as integer sample values. Raw
// voltage signals render each tip as a conductivity/optical probe would see it:
// the level switches between voltage_water and voltage_air with a first-order
// response of time constant tau (per sample: v <- L + (v - L) exp(-1/(fs tau))),
// Gaussian noise is added and the result is quantised to int16 counts,
// volts = counts * voltage_full_scale / 32768.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "awcc/air_intervals.hpp"
#include "synth/random.hpp"
#include "synth/scene.hpp"

namespace synth {

enum class FileFormat { flac, wav, w64, rf64, hdf5 };
enum class SignalKind { binary, voltage };

std::string_view to_string(FileFormat format);
std::string_view to_string(SignalKind signal);
/// Format from a file extension (.flac, .wav, .w64, .rf64, .h5 or .hdf5), if known.
std::optional<FileFormat> format_from_extension(const std::filesystem::path& path);

struct RecordingOptions {
  FileFormat format = FileFormat::flac;
  SignalKind signal = SignalKind::binary;
  std::int64_t block_frames = 1 << 16;  ///< frames rendered and written at a time (results do not depend on it)
  double flac_compression = 0.0;        ///< libsndfile FLAC compression level, 0 (fastest) to 1 (smallest)
  std::function<void(double)> progress; ///< fraction done, once per block
};

/// Why a scene and format cannot be written; empty when they can.
std::string check_recordable(const Scene& scene, std::size_t channels, FileFormat format);

/// Renders raw voltage counts tip by tip, block after block. Noise is drawn
/// sample by sample, tip by tip, from the scene's noise stream, so any block
/// size gives the same counts.
class VoltageRenderer {
 public:
  VoltageRenderer(const Scene& scene, std::size_t tips);
  /// air[j][i] is 1 where tip j is in air at frame i of the block; writes
  /// interleaved int16 counts (frames x tips).
  void render(const std::vector<std::span<const std::uint8_t>>& air, std::span<std::int16_t> interleaved);
  [[nodiscard]] double volts_per_count() const { return full_scale_ / 32768.0; }

 private:
  Rng rng_;
  double water_, air_, decay_, noise_, full_scale_;
  std::vector<double> state_;
  bool started_ = false;
};

/// Writes the signals to `path` (atomically: temporary name, then rename).
/// Throws OptionError (a scene or format this container cannot hold) or
/// OutputError, naming the file and the fix.
void write_recording(const std::filesystem::path& path, const Scene& scene,
                     std::span<const awcc::AirIntervals> signals, const RecordingOptions& options = {});

/// Reads every frame of an audio recording back as int16 (tests and small files).
/// Returns frames x channels interleaved and sets channels and fs.
std::vector<std::int16_t> read_recording_int16(const std::filesystem::path& path, int& channels, double& fs);

}  // namespace synth
