#pragma once
// Outputs appear complete or not at all: they are written under a temporary
// name beside the target and renamed over it when the writer succeeds. A
// failure removes the temporary file, so a crash or an error never leaves a
// partial output under the real name.

#include <filesystem>
#include <functional>

namespace awcc {

/// Calls write(temporary_path), then renames the temporary file to `target`.
/// If write throws, the temporary file is removed and the exception rethrown.
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path&)>& write);

/// Throws OutputError when the folder `target` would be written into does not
/// exist (checked before several outputs are written, so that none is).
void check_output_folder(const std::filesystem::path& target);

/// Writes text to `target` atomically.
void write_text_atomically(const std::filesystem::path& target, std::string_view text);

}  // namespace awcc
