// The readers' shared support (reader_support.hpp).
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <stdexcept>

#include "awcc/errors.hpp"
#include "awcc/pdpsim_layout.hpp"
#include "awcc/units.hpp"
#include "reader_support.hpp"

namespace awcc {

std::int64_t Recording::read_int16(std::span<std::int16_t>, std::int64_t) {
  throw std::logic_error("read_int16 on a recording without 16-bit integer samples");
}

namespace detail {

void reader_fail(const std::filesystem::path& path, std::string_view what, std::string quantity) {
  throw InputError(fmt::format("{}: {}", path.string(), what), std::move(quantity));
}

// To 1e-6 by default: a CSV's time stamps are rounded.
double stated_rate(const std::filesystem::path& path, const ReaderOptions& options, double recorded,
                   const std::string& where, double tolerance) {
  if (!(options.fs > 0.0)) return recorded;
  if (options.override_fs || std::fabs(options.fs - recorded) <= tolerance * recorded) return options.fs;
  reader_fail(path,
              fmt::format("{} records a sampling rate of {} but {} was stated; leave the rate out, or force the "
                          "stated one",
                          where, format_quantity(recorded, Dimension::frequency),
                          format_quantity(options.fs, Dimension::frequency)),
              "override-fs");
}

void check_finite(const std::filesystem::path& path, std::span<const float> values, std::int64_t first_frame, int channels) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) [[unlikely]] {
      reader_fail(path, fmt::format("sample {} of channel {} (frame {}) is {}; the recording is damaged: repair or cut "
                             "it before processing",
                             first_frame + static_cast<std::int64_t>(i) / channels, static_cast<int>(i) % channels,
                             first_frame + static_cast<std::int64_t>(i) / channels,
                             std::isnan(values[i]) ? "NaN" : "infinite"));
    }
  }
}

std::string leading_bytes(const std::filesystem::path& path, std::size_t n) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes(n, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(n));
  bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return bytes;
}

// The writer in libsynth takes the same lock (libcore owns it).
std::mutex& hdf5_library_mutex() { return pdpsim::hdf5_mutex(); }

}  // namespace detail

}  // namespace awcc
