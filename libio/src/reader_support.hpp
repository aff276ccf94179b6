#pragma once
// What the readers of awcc/recording.hpp share (not installed): the refusal,
// the rule for a rate the file records itself, byte loading, the library
// lock, and each format's entry points, which the registry (formats.cpp)
// lists.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>

#include "awcc/recording.hpp"

namespace awcc::detail {

/// Throws InputError "PATH: what"; `quantity` names the reader setting that fixes it.
[[noreturn]] void reader_fail(const std::filesystem::path& path, std::string_view what, std::string quantity = {});

/// The sampling rate of a file that records its own: the stated one must
/// agree with it (to `tolerance`) unless forced.
double stated_rate(const std::filesystem::path& path, const ReaderOptions& options, double recorded,
                   const std::string& where, double tolerance = 1e-6);

/// A value of type T stored at `p`, its bytes reversed when `swap`.
template <class T>
T load(const void* p, bool swap) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

/// Refuses a recording of interleaved samples (frame after frame of
/// `channels` values) whose stated channel count does not fit its data: a
/// header saying 3 channels over data of 2 deinterleaves into channels that
/// each mix both tips, which no later step can tell from a flow. Reads the
/// first block and rewinds. `stated` names where the count comes from (a
/// header field, a stated layout), `fix(n)` the remedy when the data hold n
/// channels, `quantity` the reader setting that fixes it.
void check_interleaving(Recording& recording, std::string_view stated, const std::function<std::string(int)>& fix,
                        std::string quantity = {});

/// The first n bytes of a file (fewer when it is shorter): what magic tests look at.
std::string leading_bytes(const std::filesystem::path& path, std::size_t n);

/// Refuses a block of interleaved samples holding a NaN or an infinity,
/// naming the sample, channel and frame (first_frame: the block's first).
void check_finite(const std::filesystem::path& path, std::span<const float> values, std::int64_t first_frame,
                  int channels);

/// libhdf5 may be built without its thread-safety option (Debian 12's
/// 1.10.8 has it; other builds do not), matio keeps global log state and
/// reads v7.3 files through libhdf5: every call into either holds this lock
/// (awcc::pdpsim::hdf5_mutex, shared with libsynth's writer), so recordings
/// may be opened, read and written from several threads at once.
std::mutex& hdf5_library_mutex();

// Each format's reader (its own file): how it opens a file, and how it
// knows one by its first bytes. The registry in formats.cpp names them.

/// Every container libsndfile reads; magic: RIFF, RF64, fLaC, FORM, OggS, ...
std::unique_ptr<Recording> open_sndfile(const std::filesystem::path& path, const ReaderOptions& options);
bool audio_magic(const std::filesystem::path& path);
/// The UQ LabVIEW .dat layout (no magic: its header is two counts).
std::unique_ptr<Recording> open_uq_dat(const std::filesystem::path& path, const ReaderOptions& options);
/// Headerless raw samples in the stated layout (no magic).
std::unique_ptr<Recording> open_raw(const std::filesystem::path& path, const ReaderOptions& options);
/// Column files: CSV, TSV, LabVIEW .lvm; magic: the first bytes are text.
std::unique_ptr<Recording> open_csv(const std::filesystem::path& path, const ReaderOptions& options);
bool looks_like_text(const std::filesystem::path& path);
/// NI TDMS; magic: the lead-in "TDSm".
std::unique_ptr<Recording> open_tdms(const std::filesystem::path& path, const ReaderOptions& options);
bool tdms_magic(const std::filesystem::path& path);
/// HDF5; magic: the HDF5 signature at 0 or a user-block offset.
std::unique_ptr<Recording> open_hdf5(const std::filesystem::path& path, const ReaderOptions& options);
bool hdf5_magic(const std::filesystem::path& path);
/// MATLAB .mat, v5 and v7.3; magic: the text header "MATLAB 5.0 MAT-file", "MATLAB 7.3 MAT-file".
std::unique_ptr<Recording> open_matlab(const std::filesystem::path& path, const ReaderOptions& options);
bool matlab_magic(const std::filesystem::path& path);

}  // namespace awcc::detail
