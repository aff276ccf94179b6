#pragma once
// Results as MATLAB variables (issue 54): what a JSON of pdp holds, written
// with matio so that `r = load('results.mat')` in MATLAB (or
// scipy.io.loadmat) gives the same tree, plus tables ready for
// struct2table. The one owner of the mapping:
//
//  - each top-level key of the document is a variable;
//  - an object is a 1x1 struct, a key its field;
//  - an array of numbers (null as NaN) is a 1xN double row, of booleans a
//    1xN logical row, of equally long number arrays an NxM double matrix, of
//    objects a 1xN struct array (the union of their keys; a key an element
//    lacks is []), of anything else a 1xN cell array; an empty array is [];
//  - a number is a double, a boolean a logical, a string a char row (UTF-8),
//    null [];
//  - a key that is no MATLAB name becomes one: each character outside
//    [A-Za-z0-9_] an underscore, an 'x' before a first character that is no
//    letter, cut to 63 characters (the quantile "0.025" is x0_025); the
//    original keys of a struct whose names changed are kept in its field
//    json_keys (a cell row of the original keys, in field order).
//
// A table (MatTable) is a struct of equally long column vectors, doubles or
// cell columns of text, and beside it the struct NAME_units with each
// column's unit ("-" dimensionless, "" text), so that struct2table(r.NAME)
// is the table and r.NAME_units.velocity its unit.
//
// Version 5 by default (MATLAB's -v7 without compression: every MATLAB and
// scipy.io.loadmat read it); version 7.3 (HDF5) when asked, or when a
// variable would exceed version 5's 2 GiB.

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>
#include <vector>

namespace awcc {

enum class MatVersion { v5, v7_3 };

/// A table written as a struct of columns with its units.
struct MatTable {
  struct Column {
    std::string name;
    std::string unit;                                                      ///< "-" dimensionless, "" text
    std::variant<std::vector<double>, std::vector<std::string>> values;  ///< one per row
  };
  std::string name;  ///< the variable (a MATLAB name)
  std::vector<Column> columns;
};

/// A MATLAB name for `key` (the header's rule).
std::string matlab_name(const std::string& key);

/// Writes `document` and `tables` to `path` (replaced if present) as the
/// header describes. `version` v5 moves to v7.3 when a variable exceeds
/// 2 GiB. Throws awcc::OutputError naming the path when matio cannot write
/// it, std::invalid_argument for a table whose columns differ in length or
/// whose name is no MATLAB name.
void write_mat(const std::filesystem::path& path, const nlohmann::json& document,
               const std::vector<MatTable>& tables = {}, MatVersion version = MatVersion::v5);

}  // namespace awcc
