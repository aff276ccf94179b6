// Every reader and the whole processing chain (binarisation, phase
// statistics, FSCC, AWCC) on arbitrary bytes. The first byte picks the
// container (by extension: libsndfile, UQ .dat, raw of each sample type, CSV, TDMS,
// HDF5, MATLAB .mat),
// the rest is the file.
#include "awcc/json_text.hpp"
#include "awcc/serialise.hpp"
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include <hdf5.h>

#include "awcc/process.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* extensions[] = {".wav", ".flac", ".dat", ".raw", ".csv", ".tsv",
                                     ".w64", ".aiff", ".tdms", ".h5", ".mat"};
  const std::uint8_t selector = data[0];
  const auto path = fuzz::scratch(std::string("input") + extensions[selector % 11]);
  fuzz::write(path, data + 1, size - 1);
  awcc::ProcessOptions o;
  o.reader.fs = 10000.0;
  o.reader.raw.sample_type = static_cast<awcc::SampleType>((selector >> 3) % 4);
  o.reader.raw.byte_order = (selector >> 5) & 1 ? awcc::ByteOrder::big : awcc::ByteOrder::little;
  o.reader.raw.channels = 1 + ((selector >> 6) & 1) + 1;  // 2 or 3
  o.dx = 5e-3;
  o.awcc = true;
  o.fscc_options.max_lag = 0.01;
  // Every rule but fixed (which needs a voltage).
  static const awcc::ThresholdRule rules[] = {awcc::ThresholdRule::histogram, awcc::ThresholdRule::felder,
                                              awcc::ThresholdRule::kramer, awcc::ThresholdRule::hysteresis};
  o.binarisation.rule = rules[(selector >> 2) % 4];
  o.block_frames = 1 + (selector % 7) * 1000;
  try {
    const auto r = awcc::process_recording(path, o);
    (void)awcc::json_text(awcc::to_json(r));  // every result can be written
    (void)r.report();
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {
  }
  // libhdf5's own error-path leaks are suppressed (fuzz/lsan.supp); a handle
  // the HDF5 or .mat reader forgets to close is ours, and is caught here.
  if (const ssize_t open = H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL); open != 0) {
    std::fprintf(stderr, "fuzz_recording: %zd HDF5 object(s) left open\n", open);
    std::abort();
  }
  std::filesystem::remove(path);
  return 0;
}
