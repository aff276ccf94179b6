#pragma once
// --mat and --mat-v73, declared once for every subcommand that writes a JSON
// (process, correct, validate): the JSON's content as MATLAB variables
// (awcc/mat_output.hpp), and the profile's rows as a table when the JSON
// holds a profile.

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "awcc/mat_output.hpp"

namespace pdp {

struct MatOption {
  std::string path;  ///< --mat FILE; empty = none
  bool v73 = false;  ///< --mat-v73

  [[nodiscard]] awcc::MatVersion version() const { return v73 ? awcc::MatVersion::v7_3 : awcc::MatVersion::v5; }
};

/// Registers --mat (its help names what `tables` the subcommand adds beside
/// the JSON's content) and --mat-v73 in `group`.
void add_mat_options(CLI::App* cmd, MatOption& o, const std::string& tables, const std::string& group = {});

/// The profile's rows of a pdp JSON (its "profile" array) as the table
/// profile_table: one column per profile CSV column (awcc::profile_csv_columns,
/// and correction::correction_csv_columns when a row is corrected) read at its
/// JSON pointer. A column is numbers (a switch as 1/0, NaN where a row has
/// none) when it has a unit or every value is a number or a switch, text
/// otherwise ("" where a row has none, a list joined by "; ", a file by its
/// name). Nothing when there is no profile.
std::vector<awcc::MatTable> profile_mat_tables(const nlohmann::json& document);

}  // namespace pdp
