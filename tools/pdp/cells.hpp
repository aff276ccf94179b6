#pragma once
// Cells of the CSV files and lists pdp reads (sweep CSVs, profile CSVs,
// option lists): no quoting, as pdp writes them.

#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace pdp {

/// The cells of a line, an empty last cell kept ("a," is two cells).
inline std::vector<std::string> split_cells(const std::string& line, char separator = ',') {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const auto at = line.find(separator, start);
    out.push_back(line.substr(start, at == std::string::npos ? std::string::npos : at - start));
    if (at == std::string::npos) return out;
    start = at + 1;
  }
}

/// The finite number a whole cell holds, or nothing.
inline std::optional<double> cell_number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace pdp
