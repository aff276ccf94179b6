// One reader, parse only: the input opened as the format PDP_FUZZ_FORMAT
// names (the registry's name: dat, raw, csv, sndfile, tdms, hdf5, mat) and
// every block read, with no processing, so that each execution is cheap and
// the fuzzer's depth goes into the reader. Built once per format
// (fuzz/CMakeLists.txt: fuzz_read_<format>).
//
// Input: the first byte chooses the reader options a lab could state, the
// rest is the file.
//   bit 0: a stated rate (10 kHz) or none;  bit 1: force it (override_fs);
//   bit 2: read a truncated audio or TDMS file (allow_truncated);
//   bit 3: a stated volts per count (1 mV);
//   bit 4: the channels named: HDF5 dataset "/run", TDMS channels "lead" and
//          "probe/trail", MATLAB variables "lead" and "trail" (the seeds' names);
//   raw only, bits 3-7: sample type (2 bits), byte order, channels 1-4 (2 bits).
// The seeds (fuzz/make_seeds.cpp) carry that byte too.
//
// What counts as a finding, beyond a crash, a sanitizer report, a timeout or
// an allocation over the RSS limit:
//  - an exception that is not awcc::InputError, or one whose message does not
//    start with the file's path (readers name the file);
//  - a recording that opens with no channel, no positive rate, or fewer
//    frames read than RecordingInfo::frames announces without a refusal, or
//    more; a sample handed out that is not finite (NaN, infinite: readers
//    refuse them, naming the sample);
//  - a second pass after rewind() that differs from the first (its first
//    block), and a 16-bit pass (read_int16) that differs from the float one by
//    more than rounding: processing takes either.
//  - an HDF5 object left open after the input (hdf5 and v7.3 .mat read
//    through libhdf5; its own error-path leaks are suppressed in lsan.supp).
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/errors.hpp"
#include "awcc/recording.hpp"
#include "fuzz_util.hpp"

#ifndef PDP_FUZZ_FORMAT
#error "PDP_FUZZ_FORMAT names the reader (fuzz/CMakeLists.txt)"
#endif

namespace {

constexpr std::string_view kFormat = PDP_FUZZ_FORMAT;

[[noreturn]] void finding(const char* what, const std::string& detail = {}) {
  std::fprintf(stderr, "fuzz_read_%s: %s %s\n", kFormat.data(), what, detail.c_str());
  std::abort();
}

awcc::ReaderOptions options_from(std::uint8_t selector) {
  awcc::ReaderOptions o;
  o.format = std::string(kFormat);
  if (selector & 1) o.fs = 10000.0;
  o.override_fs = (selector & 2) != 0;
  o.allow_truncated = (selector & 4) != 0;
  if (kFormat == "raw") {
    o.raw.sample_type = static_cast<awcc::SampleType>((selector >> 3) & 3);
    o.raw.byte_order = (selector >> 5) & 1 ? awcc::ByteOrder::big : awcc::ByteOrder::little;
    o.raw.channels = 1 + ((selector >> 6) & 3);
    o.raw.volts_per_count = 1e-3;
  } else {
    if (selector & 8) o.volts_per_count = 1e-3;
    if (selector & 16) {
      if (kFormat == "hdf5") o.datasets = {"/run"};
      if (kFormat == "tdms") o.tdms_channels = {"lead", "probe/trail"};
      if (kFormat == "mat") o.variables = {"lead", "trail"};
    }
  }
  return o;
}

// Every block of the recording through read(); the first block kept to check rewind().
std::int64_t read_all(awcc::Recording& r, std::int64_t block, std::vector<float>& buffer, std::vector<float>& first) {
  std::int64_t total = 0;
  for (std::int64_t n; (n = r.read(buffer, block)) > 0;) {
    if (n > block) finding("read() returned more frames than asked:", std::to_string(n));
    const auto values = static_cast<std::size_t>(n) * static_cast<std::size_t>(r.info().channels);
    for (std::size_t i = 0; i < values; ++i) {
      if (!std::isfinite(buffer[i])) finding("read() handed out a sample that is not finite:", std::to_string(buffer[i]));
    }
    if (total == 0) first.assign(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(values));
    total += n;
  }
  return total;
}

// PDP_FUZZ_VERBOSE=1: say what each input gave (how the seeds are checked to be read whole).
const bool verbose = std::getenv("PDP_FUZZ_VERBOSE") != nullptr;

void check(awcc::Recording& r) {
  const awcc::RecordingInfo& info = r.info();
  if (info.channels <= 0) finding("opened with no channel");
  if (!(info.fs > 0.0) || !std::isfinite(info.fs)) finding("opened without a positive rate:", std::to_string(info.fs));
  // Blocks of at most 64 Ki values, as processing reads them (a channel
  // count the file cannot hold shows as an allocation over the limit).
  const std::int64_t block = std::clamp<std::int64_t>(65536 / info.channels, 1, 4096);
  const auto values = static_cast<std::size_t>(block) * static_cast<std::size_t>(info.channels);
  std::vector<float> buffer(values), first;
  const std::int64_t total = read_all(r, block, buffer, first);
  if (info.frames >= 0 && total != info.frames) {
    finding("read a different number of frames than announced:",
            std::to_string(total) + " read, " + std::to_string(info.frames) + " announced");
  }
  if (verbose) {
    std::fprintf(stderr, "read %lld frames x %d channels at %g Hz (%s)\n", static_cast<long long>(total), info.channels,
                 info.fs, info.description.c_str());
  }
  if (total == 0) return;
  r.rewind();
  std::vector<float> again(values);
  const std::int64_t n = r.read(again, block);
  const auto head = static_cast<std::size_t>(n) * static_cast<std::size_t>(info.channels);
  // Every sample is finite (checked above): equal means the same sample.
  if (head != first.size() || !std::equal(first.begin(), first.end(), again.begin())) {
    finding("the first block differs after rewind()");
  }
  if (!r.has_int16()) return;
  r.rewind();
  std::vector<std::int16_t> counts(values);
  std::int64_t counted = 0;
  for (std::int64_t m; (m = r.read_int16(counts, block)) > 0;) {
    if (counted == 0) {
      const auto k = std::min(first.size(), static_cast<std::size_t>(m) * static_cast<std::size_t>(info.channels));
      for (std::size_t i = 0; i < k; ++i) {
        const double volts = static_cast<double>(counts[i]) * info.quantum;
        // float volts: the count times the quantum, rounded once or twice.
        if (std::fabs(volts - first[i]) > 1e-6 * std::max(1.0, std::fabs(volts))) {
          finding("read_int16 x quantum differs from read():",
                  std::to_string(volts) + " against " + std::to_string(first[i]));
        }
      }
    }
    counted += m;
  }
  if (counted != total) {
    finding("read_int16 read a different number of frames than read():",
            std::to_string(counted) + " against " + std::to_string(total));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  // The format is stated; the extension only matters to libsndfile, which
  // guesses headerless files by it.
  constexpr std::string_view extension = kFormat == "sndfile" ? ".wav" : kFormat == "hdf5" ? ".h5" : kFormat == "csv" ? ".csv" : "";
  const auto path = fuzz::scratch("input" + (extension.empty() ? "." + std::string(kFormat) : std::string(extension)));
  fuzz::write(path, data + 1, size - 1);
  try {
    auto recording = awcc::open_recording(path, options_from(data[0]));
    check(*recording);
  } catch (const awcc::InputError& e) {
    if (verbose) std::fprintf(stderr, "refused: %s\n", e.what());
    if (!std::string_view(e.what()).starts_with(path.string())) finding("a refusal that does not name the file:", e.what());
  }
  if (kFormat == "hdf5" || kFormat == "mat") {
    if (const ssize_t open = H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL); open != 0) {
      finding("HDF5 objects left open:", std::to_string(open));
    }
  }
  std::filesystem::remove(path);
  return 0;
}
