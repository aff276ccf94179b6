// The readers' shared support (reader_support.hpp).
#include <fmt/format.h>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "awcc/errors.hpp"
#include "awcc/pdpsim_layout.hpp"
#include "awcc/sha256.hpp"
#include "awcc/units.hpp"
#include "reader_support.hpp"

namespace awcc {

std::int64_t Recording::read_int16(std::span<std::int16_t>, std::int64_t) {
  throw std::logic_error("read_int16 on a recording without 16-bit integer samples");
}

std::string Recording::sha256() { return sha256_of_file(info_.path); }

namespace detail {

void reader_fail(const std::filesystem::path& path, std::string_view what, std::string quantity) {
  throw InputError(fmt::format("{}: {}", path.string(), what), std::move(quantity));
}

// To 1e-6 by default: a CSV's time stamps are rounded.
double stated_rate(const std::filesystem::path& path, const ReaderOptions& options, double recorded,
                   const std::string& where, double tolerance) {
  // A denormal increment gives an infinite rate (found by fuzz_read_tdms):
  // no recording has one, so the header is damaged.
  if (!std::isfinite(recorded) || !(recorded > 0.0)) {
    if (options.fs > 0.0 && options.override_fs) return options.fs;
    reader_fail(path,
                fmt::format("{} gives a sampling rate of {} Hz, which no recording has: the header is damaged; state "
                            "the rate and force it",
                            where, recorded),
                "fs,override-fs");
  }
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

// The mean absolute difference D(s) between samples s apart in the flat,
// interleaved stream is smallest at s = the true channel count T (a channel
// beside its next sample: noise and the rare transition) and at its
// multiples; a stride pairing different channels meets every difference of
// level and phase between tips. A count C that T does not divide is refused
// when D(C) > 4 D(T). The factor is measured, not derived: the ten real
// recordings read as written have D(2) the least of D(1..8); read as 3
// channels (and 3-channel data as 2) D(C) is 14 to 285 times D(T). Channels
// that copy one another make a stride dividing C the least (T = 1 for a
// doubled tip), which is not refused: then the data cannot tell a copied
// channel from a count too large by a whole factor.
void check_interleaving(Recording& recording, std::string_view stated, const std::function<std::string(int)>& fix,
                        std::string quantity) {
  const int channels = recording.info().channels;
  constexpr int kMostStrides = 128;
  if (channels < 1 || 2 * channels > kMostStrides) return;
  const int strides = std::max(2 * channels, 8);
  const std::int64_t frames = (std::int64_t{1} << 17) / channels;
  std::vector<float> x(static_cast<std::size_t>(frames * channels));
  std::int64_t got = 0;
  while (got < frames) {
    const std::int64_t n = recording.read(std::span(x).subspan(static_cast<std::size_t>(got * channels)), frames - got);
    if (n <= 0) break;
    got += n;
  }
  recording.rewind();
  const auto samples = static_cast<std::size_t>(got * channels);
  // Too short to judge: fewer than 64 pairs per stride.
  if (samples < 64 * static_cast<std::size_t>(strides) + static_cast<std::size_t>(strides)) return;
  std::vector<double> d(static_cast<std::size_t>(strides) + 1, 0.0);
  for (int s = 1; s <= strides; ++s) {
    double sum = 0.0;
    for (std::size_t i = 0; i + static_cast<std::size_t>(s) < samples; ++i) {
      sum += std::fabs(static_cast<double>(x[i + static_cast<std::size_t>(s)]) - static_cast<double>(x[i]));
    }
    d[static_cast<std::size_t>(s)] = sum / static_cast<double>(samples - static_cast<std::size_t>(s));
  }
  int best = 1;
  for (int s = 2; s <= strides; ++s) {
    if (d[static_cast<std::size_t>(s)] < d[static_cast<std::size_t>(best)]) best = s;
  }
  const double at_stated = d[static_cast<std::size_t>(channels)], at_best = d[static_cast<std::size_t>(best)];
  if (channels % best == 0 || !(at_stated > 4.0 * at_best)) return;
  const char* unit = recording.info().volts_known ? " V" : " (full scale 1)";
  reader_fail(recording.info().path,
              fmt::format("{} says {} channels, but the samples repeat as {} channels: samples {} apart differ by "
                          "{:.3g}{} on average, {} apart by {:.3g}{}, so each channel read as stated would mix several "
                          "tips; {}",
                          stated, channels, best, best, at_best, unit, channels, at_stated, unit, fix(best)),
              std::move(quantity));
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
