#include "awcc/atomic_output.hpp"

#include <fmt/format.h>
#include <fstream>
#include <stdexcept>
#include <unistd.h>

#include "awcc/errors.hpp"

namespace awcc {

void check_output_folder(const std::filesystem::path& target) {
  namespace fs = std::filesystem;
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  // A folder named as the output (or a path ending in a separator) would be
  // renamed over, or the temporary file named in the error: said here.
  std::error_code ec;
  if (!target.has_filename() || fs::is_directory(target, ec)) {
    throw OutputError(
        fmt::format("{}: is a folder, not a file; name the output file (a path in the folder)", target.string()));
  }
  if (!fs::is_directory(parent)) {
    throw OutputError(fmt::format("{}: the folder {} does not exist; create it or choose another output path",
                                  target.string(), parent.string()));
  }
}

void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path&)>& write) {
  namespace fs = std::filesystem;
  check_output_folder(target);
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const fs::path temporary =
      parent / fmt::format(".{}.{}.partial", target.filename().string(), static_cast<long>(::getpid()));
  try {
    write(temporary);
    fs::rename(temporary, target);
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
}

void write_text_atomically(const std::filesystem::path& target, std::string_view text) {
  write_atomically(target, [&](const std::filesystem::path& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    // The target named, not the temporary file: that is the path the user gave.
    if (!out) {
      throw OutputError(
          fmt::format("{}: could not write the file (no permission to write in its folder, or the disk "
                      "is full)",
                      target.string()));
    }
  });
}

}  // namespace awcc
