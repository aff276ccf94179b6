#pragma once
// Every quantity a reader's error carries must be the declared name of a
// reader option (or several, comma-separated): the command line turns it
// into its flag and Python into its keyword by one rule, with no table.

#include <algorithm>
#include <string>
#include <string_view>
#include "awcc/options.hpp"
#include "awcc/csv.hpp"

inline bool declared_reader_quantity(std::string_view quantity) {
  if (quantity.empty()) return true;
  const auto fields = awcc::reader_option_fields();
  for (const auto& name : awcc::split_cells(quantity)) {
    if (std::none_of(fields.begin(), fields.end(), [&](const auto& f) { return name == f.name; })) return false;
  }
  return true;
}
