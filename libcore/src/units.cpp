#include "awcc/units.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace awcc {
namespace {

struct Unit {
  std::string_view symbol;
  double scale;  // SI value of one unit
};

std::vector<Unit> units_of(Dimension dimension) {
  switch (dimension) {
    case Dimension::dimensionless:
      return {{"%", 0.01}};
    case Dimension::length:
      return {{"m", 1.0}, {"cm", 1e-2}, {"mm", 1e-3}, {"um", 1e-6}, {"µm", 1e-6}};
    case Dimension::time:
      return {{"s", 1.0}, {"ms", 1e-3}, {"us", 1e-6}, {"µs", 1e-6}, {"ns", 1e-9},
              {"min", 60.0}, {"h", 3600.0}};
    case Dimension::frequency:
      return {{"Hz", 1.0}, {"kHz", 1e3}, {"MHz", 1e6}, {"GHz", 1e9}};
    case Dimension::velocity:
      return {{"m/s", 1.0}, {"cm/s", 1e-2}, {"mm/s", 1e-3}, {"km/h", 1.0 / 3.6}};
    case Dimension::voltage:
      return {{"V", 1.0}, {"mV", 1e-3}};
    case Dimension::angle:
      return {{"rad", 1.0}, {"deg", std::numbers::pi / 180.0}};
    case Dimension::density:
      return {{"kg/m3", 1.0}, {"g/cm3", 1e3}};
    case Dimension::kinematic_viscosity:
      return {{"m2/s", 1.0}, {"mm2/s", 1e-6}};
    case Dimension::surface_tension:
      return {{"N/m", 1.0}, {"mN/m", 1e-3}};
    case Dimension::discharge_per_width:
      return {{"m2/s", 1.0}, {"m3/s/m", 1.0}, {"l/s/m", 1e-3}, {"L/s/m", 1e-3}};
  }
  return {};
}

std::string_view dimension_name(Dimension dimension) {
  switch (dimension) {
    case Dimension::dimensionless: return "a plain number";
    case Dimension::length: return "a length";
    case Dimension::time: return "a time";
    case Dimension::frequency: return "a frequency";
    case Dimension::velocity: return "a velocity";
    case Dimension::voltage: return "a voltage";
    case Dimension::angle: return "an angle";
    case Dimension::density: return "a density";
    case Dimension::kinematic_viscosity: return "a kinematic viscosity";
    case Dimension::surface_tension: return "a surface tension";
    case Dimension::discharge_per_width: return "a discharge per unit width";
  }
  return "a quantity";
}

// The unit a lab usually writes for a dimension, and the SI one.
std::pair<std::string_view, std::string_view> usual_units(Dimension dimension) {
  switch (dimension) {
    case Dimension::length: return {"mm", "m"};
    case Dimension::time: return {"s", "ms"};
    case Dimension::frequency: return {"Hz", "kHz"};
    case Dimension::velocity: return {"m/s", "cm/s"};
    case Dimension::voltage: return {"V", "mV"};
    case Dimension::angle: return {"deg", "rad"};
    case Dimension::density: return {"kg/m3", "g/cm3"};
    case Dimension::kinematic_viscosity: return {"m2/s", "mm2/s"};
    case Dimension::surface_tension: return {"N/m", "mN/m"};
    case Dimension::discharge_per_width: return {"m2/s", "l/s/m"};
    case Dimension::dimensionless: break;
  }
  return {"", ""};
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

}  // namespace

std::string_view si_unit(Dimension dimension) {
  return dimension == Dimension::dimensionless ? std::string_view{} : units_of(dimension).front().symbol;
}

std::string accepted_units(Dimension dimension) {
  std::string out;
  for (const auto& u : units_of(dimension)) {
    if (u.symbol.empty()) continue;
    if (!out.empty()) out += ", ";
    out += u.symbol;
  }
  return out;
}

double parse_quantity(std::string_view text, Dimension dimension) {
  const std::string_view s = trim(text);
  double value = 0.0;
  const char* first = s.data();
  const char* last = s.data() + s.size();
  if (!s.empty() && *first == '+') ++first;  // from_chars refuses a leading '+'
  const auto [ptr, ec] = std::from_chars(first, last, value);
  auto fail = [&](std::string_view why) -> double {
    const std::string units = accepted_units(dimension);
    std::string hint;
    if (dimension == Dimension::dimensionless) {
      hint = "write a plain number, or a percentage such as 25%";
    } else {
      hint = fmt::format("write a number with one of the units {}", units);
    }
    throw std::invalid_argument(
        fmt::format("'{}' is not {}: {}; {}", text, dimension_name(dimension), why, hint));
  };
  if (ec != std::errc{} || ptr == first) return fail("no number at its start");
  if (!std::isfinite(value)) return fail("the number is not finite");
  const std::string_view unit = trim(std::string_view(ptr, static_cast<std::size_t>(last - ptr)));
  if (unit.empty()) {
    // A bare number of a dimensional quantity is refused: "--dx 7.15" meant
    // millimetres and was taken as 7.15 m. Zero is zero in any unit.
    if (dimension == Dimension::dimensionless || value == 0.0) return value;
    // The number in the usual unit, and the same quantity in the other one
    // (20000 Hz is 20 kHz: not "20000kHz", a thousand times more).
    const auto [usual, other] = usual_units(dimension);
    double usual_scale = 1.0, other_scale = 1.0;
    for (const auto& u : units_of(dimension)) {
      if (u.symbol == usual) usual_scale = u.scale;
      if (u.symbol == other) other_scale = u.scale;
    }
    throw std::invalid_argument(fmt::format("{} has no unit: write {}{} (or the same as {:.6g}{})", s, s, usual,
                                            value * usual_scale / other_scale, other));
  }
  for (const auto& u : units_of(dimension)) {
    if (u.symbol == unit) return value * u.scale;
  }
  // A European decimal comma (7,15mm) or a list (5mm,6mm) where one value belongs.
  if (unit.size() > 1 && unit[0] == ',' && std::isdigit(static_cast<unsigned char>(unit[1]))) {
    std::string point(s);
    point[static_cast<std::size_t>(ptr - s.data())] = '.';
    throw std::invalid_argument(fmt::format("'{}' is not {}: its decimal separator is a comma; write {}", text,
                                            dimension_name(dimension), point));
  }
  if (unit.find(',') != std::string_view::npos) {
    throw std::invalid_argument(
        fmt::format("'{}' is not {}: it is a list; give one value", text, dimension_name(dimension)));
  }
  // Units are case-sensitive (mHz is not MHz): a unit in the wrong case is named with the right one.
  std::string near;
  int matches = 0;
  for (const auto& u : units_of(dimension)) {
    if (u.symbol.size() != unit.size() || u.symbol.empty()) continue;
    const bool same = std::equal(unit.begin(), unit.end(), u.symbol.begin(), [](char a, char b) {
      return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
    });
    if (same) {
      near = u.symbol;
      ++matches;
    }
  }
  if (matches == 1)
    return fail(fmt::format("unknown unit '{}' (units are case-sensitive: did you mean {}?)", unit, near));
  return fail(fmt::format("unknown unit '{}'", unit));
}

std::string format_quantity(double value, Dimension dimension) {
  if (!std::isfinite(value)) return fmt::format("{}", value);
  const double a = std::fabs(value);
  std::string_view symbol = si_unit(dimension);
  double scale = 1.0;
  switch (dimension) {
    case Dimension::length:
      if (a != 0.0 && a < 1e-3) { symbol = "um"; scale = 1e-6; }
      else if (a != 0.0 && a < 1.0) { symbol = "mm"; scale = 1e-3; }
      else if (a == 0.0) { symbol = "mm"; scale = 1e-3; }
      break;
    case Dimension::time:
      if (a != 0.0 && a < 1e-3) { symbol = "us"; scale = 1e-6; }
      else if (a != 0.0 && a < 1.0) { symbol = "ms"; scale = 1e-3; }
      break;
    case Dimension::frequency:
      if (a >= 1e6) { symbol = "MHz"; scale = 1e6; }
      else if (a >= 1e3) { symbol = "kHz"; scale = 1e3; }
      break;
    case Dimension::angle:  // a lab writes degrees
      symbol = "deg";
      scale = std::numbers::pi / 180.0;
      break;
    default:
      break;
  }
  return fmt::format("{:.10g}{}", value / scale, symbol);
}

long long parse_whole(std::string_view text, long long lo, long long hi) {
  const double v = parse_quantity(text, Dimension::dimensionless);
  if (v != std::floor(v) || v < static_cast<double>(lo) || v > static_cast<double>(hi)) {
    throw std::invalid_argument(fmt::format("'{}' must be a whole number in [{}, {}]", text, lo, hi));
  }
  return static_cast<long long>(v);
}

std::vector<std::array<double, 3>> parse_points(std::string_view text) {
  std::vector<std::array<double, 3>> points;
  std::size_t pos = 0;
  while (true) {
    const std::size_t end = std::min(text.find(';', pos), text.size());
    const std::string_view point = text.substr(pos, end - pos);
    const auto index = points.size();
    if (std::count(point.begin(), point.end(), ',') != 2) {
      throw std::invalid_argument(fmt::format("point {} '{}' needs exactly three coordinates x,y,z", index, point));
    }
    std::array<double, 3> c{};
    std::size_t p = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t comma = k < 2 ? point.find(',', p) : point.size();
      try {
        c[k] = parse_quantity(point.substr(p, comma - p), Dimension::length);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(fmt::format("point {} '{}', coordinate {}: {}", index, point, "xyz"[k], e.what()));
      }
      p = comma + 1;
    }
    points.push_back(c);
    if (end == text.size()) break;
    pos = end + 1;
  }
  return points;
}

std::string format_points(std::span<const std::array<double, 3>> points) {
  std::string out;
  for (const auto& p : points) {
    out += fmt::format("{}{},{},{}", out.empty() ? "" : ";", format_quantity(p[0], Dimension::length),
                       format_quantity(p[1], Dimension::length), format_quantity(p[2], Dimension::length));
  }
  return out;
}

}  // namespace awcc
