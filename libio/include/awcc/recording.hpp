#pragma once
// Reading probe recordings, block by block, whatever wrote them.
//
// Formats:
//  - every container libsndfile reads (WAV, W64, RF64, FLAC, AIFF, ...);
//  - the UQ LabVIEW .dat layout: two little-endian int32 (rows, channels), then
//    rows x channels little-endian int16, volts = counts * 5 / 32768;
//  - headerless raw files with a stated layout (sample type, byte order,
//    channels, header bytes, volts per count);
//  - column files (CSV, TSV, semicolon-separated with decimal commas, LabVIEW
//    .lvm text, its rows with or without the trailing Comment cell, its
//    segments read as one recording; header row optional, a time column
//    found by name or by its values);
//  - NI TDMS (LabVIEW's binary logger), written from NI's published format:
//    segments of lead-in, metadata and raw data, interleaved or not, int16,
//    int32, float32 and float64 channels with linear scaling properties,
//    wf_increment as 1 / fs; the channels are every numeric channel in file
//    order, or those named (`tdms_channels`);
//  - HDF5: pdp-sim's signal layout (dataset `signal`, samples x sensors, a
//    `time` dataset, attribute `sensor_id`) or any layout with the datasets
//    named (`datasets`: one 2-D dataset samples x channels, or one 1-D
//    dataset per channel), the rate from an attribute, a time dataset or fs;
//  - MATLAB .mat, v5 and v7.3: the variables named (`variables`: one matrix
//    samples x channels or one vector per channel), or the single numeric
//    matrix with two or more columns.
// A time base (a time column, dataset or variable) gives the rate by one rule
// (awcc/detail/time_base.hpp): the mean step, every step within 0.1 % of it,
// a stated rate agreeing within 0.1 %. The formats, their names, extensions
// and detection are one registry (libio/src/formats.cpp).
// Every reader hands out interleaved float volts (frames x channels) in
// blocks, so memory does not depend on the file's length; rewind() starts
// again for a second pass. Damaged input is refused with a message naming the
// file, what is wrong, where, and the fix; so is a stated channel count (a
// .dat or audio header, a raw layout, an .lvm Channels line) that the data
// contradict.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace awcc {

/// The formats read, by name: "sndfile", "dat", "raw", "csv", "tdms", "hdf5",
/// "mat", as listed to users; kAutomaticFormat is not among them. A name, not
/// an enumeration: the registry (libio/src/formats.cpp) owns the list, so that
/// a new format is its reader plus one row there.
std::span<const std::string_view> input_formats();
/// ReaderOptions::format for "detect it by extension and content".
inline constexpr std::string_view kAutomaticFormat = "auto";

enum class SampleType { int16, int32, float32, float64 };
enum class ByteOrder { little, big };

std::string_view to_string(SampleType type);

/// Layout of a headerless raw file (all fields stated by the user).
struct RawLayout {
  SampleType sample_type = SampleType::int16;
  ByteOrder byte_order = ByteOrder::little;
  int channels = 2;
  std::int64_t header_bytes = 0;   ///< bytes to skip at the start
  double volts_per_count = 1.0;    ///< V per integer count (or per float unit)
};

struct CsvLayout {
  char delimiter = 0;              ///< 0 = detect (comma, tab, semicolon, blanks)
  std::optional<bool> header;      ///< empty = detect (a first row with a non-number is a header)
  int time_column = -2;            ///< -2 = detect by header name (time, t, time_s, seconds), -1 = none
};

struct ReaderOptions {
  std::string format{kAutomaticFormat};  ///< an input_formats() name, or kAutomaticFormat
  RawLayout raw;
  CsvLayout csv;
  /// Hz; required for .dat, raw files and CSV without a time column. A file
  /// that records its own rate (audio containers, a CSV time column) must
  /// agree with it, unless override_fs: a wrong rate scales every velocity.
  double fs = 0.0;
  bool override_fs = false;        ///< fs replaces a different rate recorded in the file
  /// Read what a WAV, W64 or RF64 file holds when its data is shorter than
  /// its header says (a recording still being written, a copy cut short),
  /// with a warning in the recording's info; refused otherwise.
  bool allow_truncated = false;
  double volts_per_count = 0.0;    ///< overrides the file's scale when > 0 (sndfile integer data, .dat)
  /// TDMS: the channels to read, by "group/channel" or "channel" (empty: every numeric channel).
  std::vector<std::string> tdms_channels;
  /// HDF5: the dataset(s) holding the channels, by path in the file ("/run/volts"):
  /// one 2-D dataset samples x channels, or one 1-D dataset per channel
  /// (empty: pdp-sim's `signal`, or the file's only numeric dataset).
  std::vector<std::string> datasets;
  /// MATLAB: the variable(s) holding the channels: one matrix samples x
  /// channels or one vector per channel (empty: the file's only numeric
  /// matrix with two or more columns).
  std::vector<std::string> variables;
};

struct RecordingInfo {
  std::filesystem::path path;
  std::string format;              ///< the input_formats() name of the reader ("array" for memory)
  std::string description;         ///< e.g. "FLAC, int16", "UQ .dat", "CSV (3 columns, time in column 0)"
  int channels = 0;                ///< data channels (a CSV time column is not one)
  double fs = 0.0;                 ///< Hz
  std::int64_t frames = -1;        ///< -1 when unknown before reading (CSV)
  double quantum = 0.0;            ///< volts per count for integer samples, 0 for floating data
  bool volts_known = false;        ///< values are in volts (not normalised units)
  std::vector<std::string> warnings;  ///< what the reader accepted but the user must know (a truncated file)
  std::vector<std::string> channel_names;  ///< a column file's names of its data channels (header or "column k")
  /// The sensor id of each channel as the file states it (pdp-sim's
  /// `sensor_id` attribute, numbers written as whole numbers: "0", "3"), or
  /// empty when the file states none.
  std::vector<std::string> sensor_ids;
  /// Where the file states each channel's tip is, m, one per channel (x
  /// streamwise, y lateral, z vertical; pdp-sim's config.json
  /// `relative_location` of the channel's sensor, or the `relative_location`
  /// attribute pdp synth writes), or empty when it states none. Only the tips'
  /// separations matter, not the origin.
  std::vector<std::array<double, 3>> tip_positions;
  /// The channel of the leading tip when tip_positions are stated (pdp-sim's
  /// sensor id 0; else channel 0).
  int leading_tip = 0;
};

class Recording {
 public:
  virtual ~Recording() = default;
  [[nodiscard]] const RecordingInfo& info() const { return info_; }
  /// Reads up to max_frames frames into `out` (at least max_frames x channels
  /// floats, interleaved volts). Returns the frames read; 0 at the end.
  /// Throws awcc::InputError on damaged data (naming file and position).
  virtual std::int64_t read(std::span<float> out, std::int64_t max_frames) = 0;
  /// Back to the first frame.
  virtual void rewind() = 0;
  /// True when the samples are 16-bit integers that read_int16() hands out
  /// as stored (volts = count * info().quantum): the fast path of binarisation.
  [[nodiscard]] virtual bool has_int16() const { return false; }
  /// Like read(), but the raw int16 counts. Only when has_int16().
  virtual std::int64_t read_int16(std::span<std::int16_t> out, std::int64_t max_frames);
  /// From here on, hash the file's bytes as they are read (for sha256()),
  /// where the reader sees them: libsndfile's containers (through its
  /// virtual I/O), UQ .dat and raw files. Other readers (CSV, TDMS, HDF5,
  /// MATLAB) leave it to sha256() to read the file.
  virtual void hash_while_reading() {}
  /// The SHA-256 of the recording's file, the provenance's: the bytes read
  /// since hash_while_reading() and the rest (awcc::FileSha256), or the whole
  /// file read now; always the digest of every byte of the file. Empty for a
  /// recording that is no file (an array in memory). Throws InputError when
  /// the file cannot be read.
  virtual std::string sha256();

 protected:
  RecordingInfo info_;

 private:
  // The registry names the format it opened (RecordingInfo::format).
  friend std::unique_ptr<Recording> open_recording(const std::filesystem::path& path, const ReaderOptions& options);
};

/// Opens a recording (detecting the format by content and extension unless
/// told). Throws awcc::InputError naming the file, the problem and the fix;
/// its quantity() is the declared name of the reader option that fixes it
/// ("dataset", "override-fs"), or empty when the file itself must change.
std::unique_ptr<Recording> open_recording(const std::filesystem::path& path, const ReaderOptions& options = {});

/// A recording held in memory (the Python module's arrays): frames x channels
/// interleaved volts. `name` stands for the file in messages. Throws
/// InputError for no channel, a length that is not whole frames, no frame, a
/// non-finite sample or a rate that is not positive.
std::unique_ptr<Recording> memory_recording(std::vector<float> interleaved, int channels, double fs,
                                            std::string name = "array");
/// The same from 16-bit counts, volts = count x quantum; `volts_known` says
/// whether quantum makes them volts (a binary 0/1 signal: quantum 1, unknown).
/// Its samples go through the int16 fast path, as a 16-bit file's do.
std::unique_ptr<Recording> memory_recording(std::vector<std::int16_t> interleaved, int channels, double fs,
                                            double quantum, bool volts_known, std::string name = "array");

}  // namespace awcc
