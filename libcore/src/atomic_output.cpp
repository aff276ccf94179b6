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
    if (!out) throw OutputError(fmt::format("{}: could not write the file", temporary.string()));
  });
}

}  // namespace awcc
