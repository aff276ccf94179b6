#pragma once
// pdp-sim's HDF5 signal layout (mattbuergler/pdp-simulator, binary_signal.h5),
// in one place because awcc::io reads it and libsynth writes it:
//  - root dataset `signal`, samples x sensors, 0 (water) / 1 (air) as uint8
//    ('u1'; pdp-sim's own tools read it back as int8);
//  - root dataset `time`, float64 seconds, one value per sample, from 0;
//  - attribute `sensor_id` on `signal`: the sensors' ids, one per column
//    (integers from pdp-sim's configuration).
// pdp's writer adds what pdp-sim leaves out, without changing the layout
// pdp-sim's tools read: an `fs` attribute (Hz) on `signal`, and for raw
// voltages (int16 counts, which pdp-sim does not produce) a `volts_per_count`
// attribute on `signal`.

#include <mutex>
#include <string>

namespace awcc::pdpsim {

inline constexpr char signal_dataset[] = "signal";
inline constexpr char time_dataset[] = "time";
inline constexpr char sensor_id_attribute[] = "sensor_id";
inline constexpr char volts_per_count_attribute[] = "volts_per_count";
inline constexpr char fs_attribute[] = "fs";

/// libhdf5 may be built without thread safety (awcc/recording.hpp's
/// readers, detail::hdf5_library_mutex): whoever calls into it holds this lock. One instance per program (an inline function's static),
/// so the simulator's writer and the readers can share it.
inline std::mutex& hdf5_mutex() {
  static std::mutex m;
  return m;
}

/// libhdf5's innermost complaint about the last failed call, as
/// " (HDF5: ...)" (printable, at most 200 characters: a damaged file's bytes
/// may be quoted), or empty; clears libhdf5's error stack. For the readers'
/// and the writer's messages alike; call it holding hdf5_mutex(). Defined
/// beside the layout (libhdf5 stays a private dependency of awcc::core).
std::string hdf5_says();

}  // namespace awcc::pdpsim
