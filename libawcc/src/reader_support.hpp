#pragma once
// What the readers of awcc/recording.hpp share (not installed).

#include <filesystem>
#include <memory>
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

}  // namespace awcc::detail
