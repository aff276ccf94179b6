#pragma once
// pdp-sim's HDF5 signal layout (mattbuergler/pdp-simulator, binary_signal.h5),
// in one place because awcc::io reads it and libsynth writes it:
//  - root dataset `signal`, samples x sensors, 0 (water) / 1 (air) as uint8
//    ('u1'; pdp-sim's own tools read it back as int8);
//  - root dataset `time`, float64 seconds, one value per sample, from 0;
//  - attribute `sensor_id` on `signal`: the sensors' ids, one per column
//    (integers from pdp-sim's configuration).
// The probe's tips are in pdp-sim's run folder beside the file: config.json
// (its input, validated by schemadef/config_schema.json) holds
// `PROBE.sensors`, a list of {"id": integer, "relative_location": [x, y, z]}
// in metres (x streamwise); the column of sensor id k is the one whose
// `sensor_id` is k (pdp-sim writes the ids in the order of that list), and
// its `mssp.py` takes sensor id 0 as the leading tip and the separations
// S_0k = location(k) - location(0).
// pdp's writer adds what pdp-sim leaves out, without changing the layout
// pdp-sim's tools read: an `fs` attribute (Hz) on `signal`; for raw voltages
// (int16 counts, which pdp-sim does not produce) a `volts_per_count`
// attribute on `signal`; and the tips' positions as a `relative_location`
// attribute on `signal` (float64, sensors x 3, m, row j the tip of column
// j), config.json's key, so that a single file carries its probe.

#include <mutex>
#include <string>

namespace awcc::pdpsim {

inline constexpr char signal_dataset[] = "signal";
inline constexpr char time_dataset[] = "time";
inline constexpr char sensor_id_attribute[] = "sensor_id";
inline constexpr char volts_per_count_attribute[] = "volts_per_count";
inline constexpr char fs_attribute[] = "fs";
inline constexpr char tip_position_attribute[] = "relative_location";
/// pdp-sim's configuration beside the file, and its keys for the probe's tips.
inline constexpr char config_file[] = "config.json";
inline constexpr char config_probe[] = "PROBE";
inline constexpr char config_sensors[] = "sensors";
inline constexpr char config_sensor_id[] = "id";
inline constexpr char config_location[] = "relative_location";

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
