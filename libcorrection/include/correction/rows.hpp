#pragma once
// Correcting results that were written to files: the process JSON (one
// recording or a profile) and the profile CSV of pdp process. Each row's
// measurement is read by the names of awcc/read_back.hpp (enums by their
// parsers there), its features made
// by the one contract (correction/features.hpp), and its processing checked
// against the model's: results processed differently are refused.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "correction/model.hpp"

namespace correction {

/// Values a file may lack, stated by the user (m, m, -).
struct RowDefaults {
  std::optional<double> dx, dy;
  std::optional<int> np;
  /// The record's sampling rate (Hz) and length (s), features of the
  /// extended models, for files that do not record them (other tools' CSVs).
  std::optional<double> fs, duration;
  /// How AWCC's moments were taken, for files that do not record it (a
  /// model with the weighting feature; empty: not known).
  std::optional<awcc::Weighting> weighting;
};

/// What a correction of a file says besides its rows.
struct FileCorrection {
  std::string text;                   ///< the corrected file (same format as the input)
  std::vector<std::string> warnings;  ///< e.g. rows whose processing the file does not record
};

/// The measurement of one result of a process JSON (a recording's object,
/// or one entry of a profile), made by measurement_of from the fields of the
/// awcc::ProcessResult the JSON was written from: the same as of the result
/// in memory. Values the file lacks come from `defaults` (dx, dy, np, fs,
/// duration) or are unknown (windows). Throws awcc::InputError (a missing
/// or mistyped key, an unknown status: naming the file, the row's JSON
/// pointer `row`, "" for a recording's file, and the value) or
/// awcc::OptionError (dx, dy or np needed and neither in the file nor the
/// defaults).
MeasurementResult measurement_of_json(const nlohmann::json& result, const RowDefaults& defaults,
                                      const std::string& file, const std::string& row = "");

/// Adds a "correction" object to every result of a process JSON. Throws
/// awcc::InputError (not such a JSON, processed differently from the model)
/// or awcc::OptionError (a value the file lacks and `defaults` does not give:
/// quantity "dx", "dy" or "np").
FileCorrection correct_process_json(const CorrectionModel& model, const std::string& text, const RowDefaults& defaults,
                                    const std::string& file, const std::string& model_name);

/// Appends the correction columns to every row of a profile CSV; same errors.
FileCorrection correct_profile_csv(const CorrectionModel& model, const std::string& text, const RowDefaults& defaults,
                                   const std::string& file);

}  // namespace correction
