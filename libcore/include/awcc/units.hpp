#pragma once
// Physical quantities written with units, as a hydraulics lab writes them:
// "5mm", "7.15 mm", "500kHz", "300s", "10m/s", "25%". A dimensional quantity
// (length, time, frequency, velocity, voltage) needs its unit: a bare number
// is refused (but 0), because "7.15" for a tip separation in millimetres
// would silently be 7.15 m. Dimensionless ones take bare numbers.

#include <array>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace awcc {

enum class Dimension {
  dimensionless,
  length,
  time,
  frequency,
  velocity,
  voltage,
  angle,                ///< rad (deg accepted)
  density,              ///< kg/m3
  kinematic_viscosity,  ///< m2/s
  surface_tension,      ///< N/m
  discharge_per_width,  ///< m2/s (l/s/m accepted): a flow's discharge per unit width
};

/// SI unit symbol of a dimension ("m", "s", "Hz", "m/s", "V", "").
std::string_view si_unit(Dimension dimension);

/// Units accepted for a dimension, for error messages ("m, cm, mm, um").
std::string accepted_units(Dimension dimension);

/// Parses a number with its unit into SI. Throws std::invalid_argument with a
/// message that names the text, the expected kind of quantity and the units
/// accepted. Non-finite numbers and bare dimensional numbers are refused.
double parse_quantity(std::string_view text, Dimension dimension);

/// A whole number in [lo, hi] ("15", "1e3"); throws std::invalid_argument
/// naming the text and the range.
long long parse_whole(std::string_view text, long long lo, long long hi);

/// Points in space, such as a probe's tips: "x,y,z;x,y,z;..." (a settings
/// file's [["0mm","0mm","0mm"], ["5mm","0mm","0mm"]] arrives in this form),
/// each coordinate a length with its unit, in metres. Throws
/// std::invalid_argument naming the point (from 0) and its text: a point
/// without exactly three coordinates, a coordinate without its unit.
std::vector<std::array<double, 3>> parse_points(std::string_view text);

/// The points as parse_points() reads them ("0mm,0mm,0mm;5mm,0mm,0mm").
std::string format_points(std::span<const std::array<double, 3>> points);

/// Formats an SI value with a readable unit ("5mm", "500kHz", "0.1s").
std::string format_quantity(double value, Dimension dimension);

}  // namespace awcc
