#pragma once
// The written forms of processing results, owned here (docs/output.md): the
// process JSON, the profile CSV (one row per recording) and the AWCC window
// table. Cells are quoted as RFC 4180 (awcc/csv.hpp).

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "awcc/process.hpp"

namespace awcc {

nlohmann::json to_json(const ProcessResult& result);
nlohmann::json to_json(const AwccOptions& options);

/// The per-window table of AWCC as CSV.
std::string awcc_windows_csv(const AwccResult& result);

/// Profile CSV: the header (no line break) and one row per recording at an
/// optional position (m).
std::string profile_csv_header();
std::string profile_csv_row(const ProcessResult& result, const std::optional<double>& position);

}  // namespace awcc
