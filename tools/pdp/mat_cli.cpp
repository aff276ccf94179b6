#include "mat_cli.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "awcc/read_back.hpp"
#include "awcc/serialise.hpp"
#include "cli_options.hpp"
#include "correction/model.hpp"

namespace pdp {

void add_mat_options(CLI::App* cmd, MatOption& o, const std::string& tables, const std::string& group) {
  auto* mat = path_option(cmd->add_option(
      "--mat", o.path,
      "write the results as MATLAB variables: the JSON's content as structs (arrays of objects as struct arrays)" +
          (tables.empty() ? std::string() : ", and " + tables + " as struct2table-ready structs with their units") +
          "; version 5 (docs/output.md)"));
  auto* v73 = cmd->add_flag("--mat-v73", o.v73,
                            "--mat as MATLAB version 7.3 (HDF5; chosen anyway when a variable exceeds version 5's "
                            "2 GiB)");
  v73->needs(mat);
  if (!group.empty()) {
    mat->group(group);
    v73->group(group);
  }
}

namespace {

// One column of profile_table: numbers (a switch as 1/0) when the column has
// a unit or every row's value is a number or a switch, text otherwise (a list
// joined by "; ", a file by its name, as in the CSV).
awcc::MatTable::Column mat_column(const awcc::ProfileColumn& c, const nlohmann::json& rows) {
  const nlohmann::json::json_pointer at{std::string(c.json_pointer)};
  std::vector<const nlohmann::json*> cells;
  bool numeric = !c.unit.empty();
  bool any = false;
  for (const auto& row : rows) {
    const auto* v = row.contains(at) && !row[at].is_null() ? &row[at] : nullptr;
    cells.push_back(v);
    if (v) any = true;
  }
  if (!numeric && any) {
    numeric = std::all_of(cells.begin(), cells.end(),
                          [](const nlohmann::json* v) { return !v || v->is_number() || v->is_boolean(); });
  }
  awcc::MatTable::Column out{std::string(c.name), std::string(c.unit), {}};
  if (numeric) {
    std::vector<double> numbers;
    for (const auto* v : cells) {
      numbers.push_back(!v || !(v->is_number() || v->is_boolean()) ? std::nan("")
                        : v->is_boolean()                          ? (v->get<bool>() ? 1.0 : 0.0)
                                                                   : v->get<double>());
    }
    out.values = std::move(numbers);
  } else {
    std::vector<std::string> texts;
    for (const auto* v : cells) {
      std::string cell;
      if (v && v->is_string()) cell = v->get<std::string>();
      else if (v && v->is_array()) {
        for (const auto& x : *v) cell += (cell.empty() ? "" : "; ") + (x.is_string() ? x.get<std::string>() : x.dump());
      } else if (v) cell = v->dump();
      if (c.name == awcc::profile_column::file) cell = std::filesystem::path(cell).filename().string();
      texts.push_back(std::move(cell));
    }
    out.values = std::move(texts);
  }
  return out;
}

}  // namespace

std::vector<awcc::MatTable> profile_mat_tables(const nlohmann::json& j) {
  if (!j.is_object() || !j.contains(awcc::process_key::profile) || !j[awcc::process_key::profile].is_array()) return {};
  const auto& rows = j[awcc::process_key::profile];
  awcc::MatTable t{"profile_table", {}};
  for (const auto& c : awcc::profile_csv_columns()) {
    if (!c.json_pointer.empty()) t.columns.push_back(mat_column(c, rows));
  }
  // A corrected profile (pdp process --correct, pdp correct): the corrected
  // CSV's columns too.
  const bool corrected = std::any_of(rows.begin(), rows.end(), [](const nlohmann::json& r) {
    return r.is_object() && r.contains("correction") && !r["correction"].is_null();
  });
  if (corrected) {
    for (const auto& c : correction::correction_csv_columns()) t.columns.push_back(mat_column(c, rows));
  }
  return {std::move(t)};
}

}  // namespace pdp
