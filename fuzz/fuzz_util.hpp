#pragma once
// Fuzz targets feed arbitrary bytes to the toolkit through the same entry
// points as a lab's files: a scratch file (in /dev/shm when there is one),
// opened by the public API. Expected refusals (std::runtime_error,
// std::invalid_argument) are fine; anything else, a crash or a sanitizer
// report is a finding.

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace fuzz {

inline std::filesystem::path scratch(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
  return dir / ("pdp-fuzz-" + std::to_string(::getpid()) + "-" + name);
}

inline void write(const std::filesystem::path& p, const std::uint8_t* data, std::size_t size) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

}  // namespace fuzz
