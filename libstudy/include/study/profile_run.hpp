#pragma once
// A profile run (issue 52): recordings at positions across a flow, each
// processed as pdp process processes one (awcc::process_recording),
// corrected when a model is given, and together a flow (METHOD 12,
// correction::profile_flow_of). The one owner of this sequence: pdp process
// and the Python module call it; their outputs are written from its result
// (profile_run_json; the profile CSV of awcc/serialise.hpp).
//
// Positions: one per file, from a list of lengths with units or from a
// manifest CSV "file,position" (a header row allowed; a file matched by its
// name, as pdp synth --profile writes it: manifest_text). A position given
// twice is refused before any recording is read, naming both files (the rule
// is awcc::repeated_position_pair's, which the flow applies again).
//
// Files. Among several inputs (a glob), one that is not a recording is
// skipped and said (ProfileRun::skipped); any other error stops the run, the
// first in file order. A file the manifest does not position is refused once
// it proves to be a recording (a README caught by the glob is skipped, not
// positioned).
//
// Threads. The recordings are processed on up to `threads` threads (0: all
// cores), each result placed by its file's index: the same numbers whatever
// the thread count.

#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "awcc/process.hpp"
#include "awcc/profile_flow.hpp"
#include "correction/model.hpp"

namespace study {

/// The positions of `files` (m) from lengths with units, one per file.
/// `source` names them in messages (the CLI's "--positions", Python's
/// "positions"). Throws std::invalid_argument.
std::vector<std::optional<double>> positions_of_list(std::span<const std::string> lengths,
                                                     std::span<const std::string> files, const std::string& source);

/// The recordings a manifest CSV names, in its rows' order, each relative to
/// the manifest's folder (as pdp synth writes it beside them). Throws
/// std::invalid_argument naming the manifest when it names none.
std::vector<std::string> files_of_manifest(const std::filesystem::path& manifest);

/// The positions of `files` from a manifest CSV (matched by file name; a file
/// without a row has none). Throws std::invalid_argument naming the manifest's
/// line: a length without its unit, a file positioned twice, two inputs of
/// one name.
std::vector<std::optional<double>> positions_of_manifest(const std::filesystem::path& manifest,
                                                         std::span<const std::string> files);

/// The manifest of recordings `names` (file names) at `positions` (m).
std::string manifest_text(std::span<const std::string> names, std::span<const double> positions);

/// Refuses (std::invalid_argument) two files given the same position, naming
/// both and `source`.
void check_distinct_positions(std::span<const std::optional<double>> positions, std::span<const std::string> files,
                              const std::string& source);

struct ProfileRunOptions {
  awcc::ProcessOptions processing;
  awcc::ProfileFlowOptions flow;
  /// Corrects every row (the model's trust rules apply); none when null.
  const correction::CorrectionModel* model = nullptr;
  /// Record each input's SHA-256 while reading it (the JSON's provenance).
  bool hash_inputs = false;
  /// Where the positions came from, for messages: a manifest's path, or
  /// empty (positions given as a list, or none).
  std::string manifest;
  /// Threads over the recordings (0: all cores).
  int threads = 0;
  /// Called with each result as it is processed, before it is corrected and
  /// the flow is made (the CLI adds its flag hints); on a worker thread.
  std::function<void(awcc::ProcessResult&)> on_result;
  /// Called with the fraction of recordings done, from the calling thread's
  /// view of the count (any thread).
  std::function<void(double)> progress;
};

struct ProfileRun {
  std::vector<awcc::ProcessResult> results;           ///< the recordings kept, in file order
  std::vector<std::optional<double>> positions;       ///< theirs, m
  std::vector<std::string> inputs;                    ///< their paths as given
  std::vector<std::string> skipped;                   ///< why each input skipped is not a recording
  std::vector<correction::Correction> corrections;    ///< one per result with a model, else none
  /// The flow of two or more files each with a position (its status says
  /// whether it could be made).
  std::optional<awcc::ProfileFlowResult> flow;
  /// One recording given on its own (not a profile).
  bool single = false;

  /// What a front end tells its user beside the outputs, one text each: a
  /// row not corrected and why, a correction's notes, the flow's warnings
  /// (the rows' own warnings are in each result).
  [[nodiscard]] std::vector<std::string> warnings() const;
};

/// Processes `files` at `positions` (one per file, or empty: none). Throws
/// what processing throws (InputError, OptionError), std::invalid_argument
/// for a file the manifest does not position and for a model trained on
/// results processed otherwise (naming what differs).
ProfileRun process_profile(std::span<const std::string> files, std::span<const std::optional<double>> positions,
                           const ProfileRunOptions& options);

/// The run as the process JSON holds it (docs/output.md): one recording's
/// object, or {"profile": [rows with position and correction], "skipped",
/// "flow"}; without provenance, which the front end adds. `model_name` is
/// written in each correction.
nlohmann::json profile_run_json(const ProfileRun& run, const std::string& model_name);

}  // namespace study
