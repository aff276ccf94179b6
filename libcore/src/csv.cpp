#include "awcc/csv.hpp"

#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

namespace awcc {

std::vector<std::string> split_cells(std::string_view line, char separator) {
  std::vector<std::string> out;
  std::string cell;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell += c;
      }
    } else if (c == '"' && cell.empty()) {
      quoted = true;
    } else if (c == separator) {
      out.push_back(std::move(cell));
      cell.clear();
    } else {
      cell += c;
    }
  }
  out.push_back(std::move(cell));
  return out;
}

CsvHeader csv_header(std::string line, char separator) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
  CsvHeader h;
  h.names = split_cells(line, separator);
  for (std::size_t i = 0; i < h.names.size(); ++i) h.index[h.names[i]] = i;
  return h;
}

std::string csv_cell(std::string_view text, char separator) {
  if (text.find_first_of(std::string{separator, '"', '\n', '\r'}) == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + '"';
}

std::optional<double> cell_number(const std::string& text) {
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

std::string csv_number(const std::optional<double>& v) { return v ? fmt::format("{:.10g}", *v) : std::string(); }

}  // namespace awcc
