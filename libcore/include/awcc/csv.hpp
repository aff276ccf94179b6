#pragma once
// Cells of the CSV files the toolkit writes and reads (profile CSVs, sweep
// CSVs, option lists), RFC 4180: a cell holding the separator, a quote or a
// line break is written in double quotes with inner quotes doubled, and read
// back the same way. One owner for every CSV of the toolkit.

#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace awcc {

/// The cells of a line, an empty last cell kept ("a," is two cells); quoted
/// cells lose their quotes.
std::vector<std::string> split_cells(std::string_view line, char separator = ',');

/// A CSV's header row: its names in order and each name's column.
struct CsvHeader {
  std::vector<std::string> names;
  std::map<std::string, std::size_t, std::less<>> index;  ///< of a name given twice, the last column
};

/// The header of a CSV's first line (a trailing carriage return dropped).
CsvHeader csv_header(std::string line, char separator = ',');

/// A cell as written: quoted when it holds the separator, a quote or a line break.
std::string csv_cell(std::string_view text, char separator = ',');

/// The finite number a whole cell holds, or nothing.
std::optional<double> cell_number(const std::string& text);

/// "%.10g" of a value, or an empty cell.
std::string csv_number(const std::optional<double>& value);

}  // namespace awcc
