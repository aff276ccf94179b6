#pragma once
// A processed recording as a row of a profile's flow quantities
// (awcc/profile_flow.hpp, METHOD 12): its position, the leading tip's void
// fraction and bubble count rate with their intervals, and the best velocity
// the row has with its uncertainty. The one builder, profile_row(RowFields):
// pdp process, pdp correct, the Python module and the report read a
// profile's rows through it, the fields taken from the ProcessResult in
// memory (row_fields) or read back from the process JSON or the profile CSV
// it was written to (profile_rows_of_json, profile_rows_of_csv), by the keys
// of awcc/read_back.hpp and correction/model.hpp.
//
// The velocity (METHOD 12): the bias-corrected AWCC median with the AWCC
// forest's quantiles where the row is corrected (not when untrusted, nor
// FSCC-forest quantiles, which correct FSCC's velocity and are named so),
// with AWCC's sampling interval as the quantiles' own part of their spread
// (awcc/profile_flow.hpp: the rest is drawn shared between the corrected
// rows); else the velocity of ProcessResult::velocity_source() (AWCC of
// quality ok, else FSCC, else AWCC of quality low) with its 95 % sampling
// interval. A velocity without an interval (FSCC whose segments give none)
// is left out: a value without uncertainty would make every interval too
// narrow; the row's note says so.
//
// The rule for a corrected row the profile should not lean on: when the
// corrected 95 % interval excludes FSCC's 95 % sampling interval (they do not
// overlap), the two methods disagree beyond their uncertainty and the row
// contributes its uncorrected velocity, with a note naming both. AWCC's low
// quality alone does not demote the corrected velocity. Both decided by
// `pdp validate --profile` over 8 seeds of each sample profile
// (docs/validation.md, "Profile intervals and the correction"): the
// exclusion rule cut the u90 and q_w errors by half with every interval
// still covering; demoting low-quality rows too put the raw velocities'
// high-Tu bias back into the rows near the invert, and N's interval covered
// 0 of 8.
//
// Read back, the JSON's numbers are the doubles written (json_text writes the
// shortest text that reads back as the same double): its rows equal the
// ProcessResults' exactly. The CSV writes 10 significant digits: its rows
// equal them to a relative 5e-10 (half a unit of the tenth digit).

#include <array>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "awcc/process.hpp"
#include "awcc/profile_flow.hpp"
#include "correction/model.hpp"

namespace correction {

/// What a row's velocity is chosen from: the few fields the choice reads.
struct RowVelocities {
  awcc::VelocitySource source = awcc::VelocitySource::none;  ///< ProcessResult::velocity_source()
  double awcc = 0.0;                                          ///< AWCC's velocity, m/s, when source is awcc
  awcc::Interval95 awcc_ci95;
  double fscc = 0.0;                                          ///< FSCC's, when source is fscc
  std::optional<awcc::Interval95> fscc_ci95;                  ///< none when its segments gave none
  /// The row's correction, when the profile was corrected.
  struct Corrected {
    bool corrected = false;  ///< status corrected (not untrusted, not refused)
    std::string forest;      ///< "awcc" or "fscc"; empty when no quantiles
    std::optional<std::array<double, correction_levels.size()>> velocity;  ///< quantiles at correction_levels
    /// The AWCC forest's: the 95 % sampling interval of AWCC's velocity (the
    /// quantiles' own part, awcc/profile_flow.hpp).
    std::optional<awcc::Interval95> awcc_ci95;
    /// FSCC's velocity and sampling interval, whatever the source: the rule
    /// of whether the profile leans on the corrected velocity reads them.
    std::optional<double> fscc;
    std::optional<awcc::Interval95> fscc_ci95;
  };
  std::optional<Corrected> correction;
};

/// Everything of a recording a profile's row reads.
struct RowFields {
  std::string name;  ///< the recording's file name
  double position = 0.0;  ///< m
  double c = 0.0;
  awcc::Interval95 c_ci95;
  double bubble_frequency = 0.0;
  awcc::Interval95 bubble_frequency_ci95;
  RowVelocities velocities;
};

struct ProfileRowOf {
  awcc::ProfileRow row;
  std::string note;  ///< why the row has no velocity, or empty
};

/// The row of `fields`: the one choice of its velocity (the header).
ProfileRowOf profile_row(const RowFields& fields);

/// The fields of `result` at `position` (m); `correction` when it was corrected.
RowFields row_fields(const awcc::ProcessResult& result, double position, const Correction* correction = nullptr);

/// The row of `result` at `position`: profile_row(row_fields(...)).
ProfileRowOf profile_row(const awcc::ProcessResult& result, double position, const Correction* correction = nullptr);

/// A profile's rows read back from a file, or why the file has none (one
/// recording; an entry without a position).
struct ProfileRowsRead {
  std::vector<ProfileRowOf> rows;
  std::string why_none;  ///< empty when rows were read
};

/// The rows of a process JSON (parsed). Throws awcc::InputError naming the
/// file, the entry's JSON pointer and the key for a missing or mistyped value.
ProfileRowsRead profile_rows_of_json(const nlohmann::json& j, const std::string& file);

/// The rows of a profile CSV of pdp process (with or without correction
/// columns); none, with why, for a CSV without the columns the rows need
/// (another tool's layout). Throws awcc::InputError naming the file, the
/// line and the column for a cell that is not what pdp writes.
ProfileRowsRead profile_rows_of_csv(const std::string& text, const std::string& file);

/// The flow quantities of `rows` with the rows' notes among the result's.
awcc::ProfileFlowResult profile_flow_of(std::vector<ProfileRowOf> rows, const awcc::ProfileFlowOptions& options);

}  // namespace correction
