#pragma once
// The written forms of processing results, owned here (docs/output.md): the
// process JSON, the profile CSV (one row per recording) and the AWCC window
// table. Cells are quoted as RFC 4180 (awcc/csv.hpp).

#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string_view>
#include <string>
#include <vector>

#include "awcc/event_detection.hpp"
#include "awcc/process.hpp"
#include "awcc/profile_flow.hpp"

namespace awcc {

/// What FSCC's and AWCC's intervals cover, as the summary (ProcessResult::report) says beside them.
inline constexpr std::string_view sampling_intervals_only =
    "FSCC's and AWCC's intervals are 95 % sampling intervals: they cover the scatter of a finite record, not the "
    "method's bias, which the bias correction (pdp correct) estimates.";

nlohmann::json to_json(const ProcessResult& result);
/// A profile's flow quantities (awcc/profile_flow.hpp): the "flow" object of a profile's JSON.
nlohmann::json to_json(const ProfileFlowResult& result);
nlohmann::json to_json(const AwccOptions& options);
nlohmann::json to_json(const StructureResult& result);
/// A tip's threshold: the keys its entry of the process JSON's "tips" holds.
nlohmann::json to_json(const Threshold& threshold);

/// Every effective option of a processing run, defaults included, by its
/// declared name (awcc/options.hpp) as text with its unit.
nlohmann::json options_json(const ProcessOptions& options);

/// An input as the provenance names it: the file and the SHA-256 of its
/// bytes when the processing hashed them as it read (ProcessResult::
/// input_sha256), or empty to hash the file now.
struct ProvenanceInput {
  std::string file;
  std::string sha256;
};

/// How an output was made: {"pdp_version", "command_line", "options"
/// (options_json), "inputs": [{"file", "bytes", "sha256"}], "utc_time"}.
nlohmann::json provenance_json(const ProcessOptions& options, const std::vector<ProvenanceInput>& inputs,
                               const std::string& command_line);

/// A column of the AWCC window table: the CSV's and the Python module's.
struct WindowColumn {
  std::string_view name;
  std::string_view unit;                       ///< "s", "m/s", "1/s", "-", "" (text)
  double (*value)(const AwccWindow&);          ///< numeric columns
  std::string_view (*text)(const AwccWindow&); ///< the text column (fate); null for numeric ones
};
/// The columns of the window table, in order.
std::span<const WindowColumn> awcc_window_columns();

/// The per-window table of AWCC as CSV.
std::string awcc_windows_csv(const AwccResult& result);

/// A column of event detection's bubble table (awcc/event_detection.hpp,
/// EventBubble): the CSV's and the Python module's.
struct BubbleColumn {
  std::string_view name;
  std::string_view unit;                          ///< "s", "m/s", "m", "-", "" (text)
  double (*value)(const EventBubble&);            ///< numeric columns (NaN: the bubble has no value)
  std::string_view (*text)(const EventBubble&);   ///< the text column (fate); null for numeric ones
};
/// The columns of the bubble table, in order: times at each tip, lags,
/// disparity, velocity, chord length, weight, fate.
std::span<const BubbleColumn> event_bubble_columns();

/// Event detection's per-bubble table as CSV, one row per leading bubble; an
/// empty cell where the bubble has no value (no candidate, no velocity).
std::string event_bubbles_csv(const EventResult& result);

/// A column of the multi-tip bubble table (awcc/multi_tip.hpp, BubbleVector).
struct VectorColumn {
  std::string_view name;
  std::string_view unit;
  double (*value)(const BubbleVector&);           ///< numeric columns (NaN: the bubble has no value)
  std::string_view (*text)(const BubbleVector&);  ///< the text column (fate); null for numeric ones
};
/// The columns of the multi-tip bubble table, in order: the leading-tip
/// time, the vector and its speed, its spread over the tip combinations,
/// diameters, the front normal, the interfacial-area share, the weight,
/// the combinations solved and skipped, the fate.
std::span<const VectorColumn> multi_tip_bubble_columns();
/// The multi-tip per-bubble table as CSV, one row per leading bubble; an
/// empty cell where the bubble has no value (no vector, Tian's sizes).
std::string multi_tip_bubbles_csv(const MultiTipResult& result);

/// A profile CSV column: its name, its unit ("" for text, "-" for a
/// dimensionless number), where the same value is in the recording's JSON
/// object (an RFC 6901 pointer; "" when it is not: the version lives in the
/// provenance) and what it is. A JSON true/false is written on/off (1/0 for
/// correction_in_range), a JSON list of warnings joined by "; ", a file by
/// its name. The report's table reads these declarations; a test checks
/// every cell of profile_csv_row against the JSON at its pointer.
struct ProfileColumn {
  std::string_view name;
  std::string_view unit;
  std::string_view json_pointer;
  std::string_view meaning;
};

/// The columns of profile_csv_header, in order.
std::span<const ProfileColumn> profile_csv_columns();

/// Profile CSV: the header (no line break, from profile_csv_columns) and one
/// row per recording at an optional position (m).
std::string profile_csv_header();
std::string profile_csv_row(const ProcessResult& result, const std::optional<double>& position);

/// The correlation functions of recordings as CSV: file, lag_s, r11, r12
/// (empty where a function has no value at that lag).
std::string correlation_functions_csv(const std::vector<const ProcessResult*>& results);

/// AWCC's velocity spectra and autocorrelations as CSV: file, quantity
/// (psd: x in Hz, value in (m/s)^2/Hz; autocorrelation: x in s), x, value,
/// below_resolvable_frequency (psd rows).
std::string velocity_spectrum_csv(const std::vector<const ProcessResult*>& results);

/// The structure outputs of a profile as CSV tables, one row per position
/// and bin or class (docs/output.md): the file suffix ("_chord_pdf.csv")
/// and its text. Recordings without structure results give no rows.
std::vector<std::pair<std::string, std::string>> structure_csv_tables(
    const std::vector<const ProcessResult*>& results, const std::vector<std::optional<double>>& positions);

}  // namespace awcc
