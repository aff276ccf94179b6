#pragma once
// What the readers of awcc/recording.hpp share (not installed).

#include <filesystem>
#include <memory>
#include <mutex>
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

/// NI TDMS (awcc/recording.hpp).
std::unique_ptr<Recording> open_tdms(const std::filesystem::path& path, const ReaderOptions& options);
/// True when the file starts with a TDMS lead-in ("TDSm").
bool tdms_magic(const std::filesystem::path& path);

/// libhdf5 may be built without its thread-safety option (Debian 12's
/// 1.10.8 has it; other builds do not), matio keeps global log state and
/// reads v7.3 files through libhdf5: every call into either holds this lock
/// (awcc::pdpsim::hdf5_mutex, shared with libsynth's writer), so recordings
/// may be opened, read and written from several threads at once.
std::mutex& hdf5_library_mutex();

/// HDF5 (awcc/recording.hpp).
std::unique_ptr<Recording> open_hdf5(const std::filesystem::path& path, const ReaderOptions& options);
/// True when the file carries the HDF5 signature (at 0 or a user-block offset).
bool hdf5_magic(const std::filesystem::path& path);

/// MATLAB .mat, v5 and v7.3 (awcc/recording.hpp).
std::unique_ptr<Recording> open_matlab(const std::filesystem::path& path, const ReaderOptions& options);
/// True when the file starts with a MAT-file's text header ("MATLAB 5.0 MAT-file", "MATLAB 7.3 MAT-file").
bool matlab_magic(const std::filesystem::path& path);

}  // namespace awcc::detail
