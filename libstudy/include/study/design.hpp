#pragma once
// pdp design: which probe geometry and settings measure a flow best, found by
// simulating the lab's own flow (METHOD 5) and processing it as the lab
// would (AWCC, METHOD 4; the bias correction, METHOD 7).
//
// Definition (TOML):
//   [design]            seeds: records simulated per condition and setting (5);
//                       seed (1); objective: "worst-case" (the largest score
//                       over the conditions, default) or "mean"; values:
//                       "corrected" (default: the model's median where it
//                       corrects, AWCC's value elsewhere) or "raw"; model: the
//                       correction model (.qrf; a model the caller gives wins)
//   [conditions.NAME]   the flow at one place, in the quantities a lab can
//                       estimate before measuring: velocity, tu, anisotropy
//                       (Tu_y/Tu_x = Tu_z/Tu_x, default 0.5), time-scale,
//                       void-fraction, bubble-diameter; each a value, a range
//                       [min, max] (uniform) or [min, max, "log"] (log-uniform):
//                       each record draws its own values. Other scene fields
//                       (synth::scene_fields) as values. At least one condition.
//   [candidates]        dx and dy: lists whose grid is tried (default 1, 2,
//                       3, 5, 7.5, 10 mm x 0, 0.5, 1, 2 mm), or probes = list of
//                       "dx,dy" (existing probes) instead; np (5, 10, 20); fs
//                       (100 kHz); duration (60 s); needle: outer diameters
//                       of the leading needle (default none: point tips).
//   [current]           optional: the lab's probe and settings (dx, dy, np, fs,
//                       duration), ranked with the candidates and named in the summary.
//
// One task simulates one record of a condition at one (fs, duration): a probe
// with the leading tip at the origin and one trailing tip per geometry, so
// that every geometry sees the same bubbles and velocity (common random
// numbers: the differences between candidates carry less noise than
// independent records would). The velocity step is the one the closest pair
// alone would get (METHOD 5: it resolves the shortest transit). Each pair
// (the leading tip with one trailing tip) is processed at each Np as pdp
// process processes a recording (awcc::process_binarised: phase statistics,
// FSCC, AWCC and the tip-order rule), and the model corrects each result's
// measurement (correction::measurement_of), with its FSCC forest where the
// AWCC forest cannot take it. Record k of a condition has seed
// derive_seed(seed, k) mixed with the condition's name, and draws its flow
// from that seed, whatever the candidates, fs or duration: adding a
// candidate changes no other row.
//
// Scores of a candidate in a condition, over its records: the error of the
// mean velocity (u / u_true - 1) and of Tu (Tu / Tu_true - 1, relative as the
// paper's +/- 20 % is), each as bias (mean), spread (sd, n - 1) and RMS
// (sqrt(bias^2 + (n - 1)/n sd^2)); the data yield; the CPU seconds of the
// processing and correction per record. The score of a candidate in a condition is RMS_u + RMS_Tu of the
// values ranked on; its objective the worst (or the mean) over conditions.
// The needle (optional): the synthetic tips are points, so a needle is not
// simulated; its slowing of the pierced bubbles (METHOD 9) is predicted per
// record from the model of Hohermuth et al. (awcc/probe_correction.hpp) at
// the record's true velocity, the leading tip's c and F and the pair's dx:
// the measured velocity u_m whose correction gives back the true u0 (found
// by bisection), and every velocity of the candidate, raw and corrected, is
// scaled by u_m / u0 (the correction model learnt needle-free records). Tu
// is a ratio of velocities and is left alone. Above c = 0.3 the model does
// not apply (not bubbly flow) and no slowing is predicted.
//
// Candidates whose records gave no value (AWCC refused, too few windows) rank
// after those without, fewest failures first; then by objective; then by
// cost: the shorter record, then the lower sampling rate (the CPU seconds
// are reported, not ranked on: they differ from run to run).

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/awcc.hpp"
#include "correction/model.hpp"
#include "synth/scene.hpp"

namespace study {

struct DesignCondition {
  std::string name;
  std::map<std::string, std::string> values;                     ///< fixed fields, as typed
  std::map<std::string, std::pair<double, double>> ranges;       ///< SI
  std::set<std::string> log_ranges;                              ///< drawn log-uniformly
};

/// A probe geometry and the settings of a record.
struct DesignCandidate {
  double dx = 0.0, dy = 0.0;  ///< m
  int np = 10;
  double fs = 0.0, duration = 0.0;  ///< Hz, s
  double needle = 0.0;        ///< outer diameter of the leading needle, m; 0 = point tips
  friend bool operator==(const DesignCandidate&, const DesignCandidate&) = default;
  friend auto operator<=>(const DesignCandidate&, const DesignCandidate&) = default;
};
/// "dx 3 mm, dy 0.5 mm, Np 10, 100 kHz, 60 s".
std::string describe(const DesignCandidate& c);

/// One record to simulate: a condition at one (fs, duration).
struct DesignTask {
  std::int64_t index = 0;
  std::size_t condition = 0;
  int record = 0;            ///< 0 .. seeds - 1
  double fs = 0.0, duration = 0.0;
  synth::Scene scene;        ///< the drawn flow, every geometry's trailing tip, fs, duration, seed
  double anisotropy = 0.5;
};

struct DesignDefinition {
  int seeds = 5;
  std::uint64_t seed = 1;
  std::string objective = "worst-case";
  std::string values = "corrected";
  std::string model;                               ///< the file's model (may be empty)
  std::vector<DesignCondition> conditions;
  std::vector<std::pair<double, double>> geometries;  ///< (dx, dy), m; the current probe's included
  std::vector<int> nps{5, 10, 20};
  std::vector<double> fss{100e3}, durations{60.0};
  std::vector<double> needles{0.0};                ///< m; 0 = none
  std::optional<DesignCandidate> current;
  std::string canonical;                           ///< for the design id

  [[nodiscard]] std::int64_t tasks() const;
  /// Task i: condition (i / (settings x seeds)), setting, record.
  [[nodiscard]] DesignTask task(std::int64_t index) const;
  /// Every candidate: geometries x Np x fs x duration.
  [[nodiscard]] std::vector<DesignCandidate> candidates() const;
  /// Result rows one task writes (geometries x Np).
  [[nodiscard]] std::int64_t rows_per_task() const;
};

/// Reads and checks a design file; throws awcc::OptionError naming the
/// file, the table and key, and the fix.
DesignDefinition load_design(const std::filesystem::path& path);

/// Design id (FNV-1a of the canonical text), as pdp sweep's study id.
std::uint64_t design_id(const DesignDefinition& d);

/// One processed pair of one record.
struct DesignRow {
  std::int64_t task = 0;
  std::string condition;
  int record = 0;
  std::uint64_t seed = 0;
  DesignCandidate candidate;
  double truth_velocity = 0.0, truth_turbulence_intensity = 0.0;
  double void_fraction = 0.0, count_rate = 0.0;  ///< leading tip, measured (the needle's slowing depends on them)
  std::optional<double> awcc_velocity, awcc_turbulence_intensity;
  std::int64_t windows_accepted = 0, windows_total = 0;
  std::optional<double> corrected_velocity, corrected_turbulence_intensity;
  std::string correction_status, correction_forest;  ///< forest empty when not corrected
  double seconds_awcc = 0.0;   ///< CPU seconds of the processing (FSCC and AWCC) and the correction
  double seconds_synth = 0.0;  ///< the record's synthesis, shared by its rows
};

/// Simulates one task's record and processes every pair at every Np (the
/// AWCC settings of `processing` otherwise; FSCC with its defaults), as pdp
/// process would, correcting with `model` when given. Rows in geometry, then
/// Np order.
std::vector<DesignRow> run_design_task(const DesignDefinition& d, const DesignTask& task,
                                       const correction::CorrectionModel* model, const awcc::AwccOptions& processing);

std::string design_rows_header();
std::string design_row_text(const DesignRow& row, std::uint64_t design);
/// The rows of this design in a runs CSV (header checked; rows of another
/// design refused; a partial last line cut off).
std::vector<DesignRow> read_design_rows(const std::filesystem::path& csv, std::uint64_t design);

/// Where an interrupted design stands.
struct DesignResume {
  std::set<std::int64_t> done;   ///< tasks whose every row is in the runs files
  std::int64_t cut_short = 0;    ///< tasks an interruption cut short: their rows removed, they run again
};
/// Reads the runs files of this design (rows of another design refused), and
/// prepares the first for appending: a task is written in one write, so a
/// crash inside it leaves it partial, and its rows go; an absent or empty
/// file gets the header.
DesignResume resume_design(const DesignDefinition& d, const std::vector<std::filesystem::path>& runs,
                           std::uint64_t design);

/// Seconds the tasks take on one thread, from a pilot of each condition and
/// rate (its first task, `pilot_seconds` of record) scaled by record length.
double estimate_design_seconds(const DesignDefinition& d, const std::vector<std::int64_t>& tasks,
                               const correction::CorrectionModel* model, const awcc::AwccOptions& processing,
                               double pilot_seconds = 2.0);

/// Error statistics of one quantity over the records.
struct ErrorStats {
  std::int64_t count = 0;
  double bias = 0.0, spread = 0.0, rms = 0.0;
};
ErrorStats error_stats(const std::vector<double>& errors);

/// A candidate in one condition.
struct ConditionScore {
  std::string condition;
  std::int64_t records = 0, failures = 0;  ///< failures: records without a value ranked on
  ErrorStats raw_u, raw_tu, corrected_u, corrected_tu;  ///< relative errors
  double corrected_fraction = 0.0;         ///< records whose value the model corrected (u)
  double data_yield = 0.0;                 ///< mean accepted / formed windows
  double seconds = 0.0;                    ///< mean AWCC CPU seconds per record
  double score = 0.0;                      ///< RMS_u + RMS_Tu of the values ranked on
};

struct RankedCandidate {
  int rank = 0;
  DesignCandidate candidate;
  bool current = false;
  std::int64_t failures = 0;
  double objective = 0.0;
  double seconds = 0.0;                    ///< mean AWCC CPU seconds per record over conditions
  /// Share of the bootstrap resamples of the records in which this candidate
  /// ranks first: how sure the recommendation is.
  double best_share = 0.0;
  std::vector<ConditionScore> conditions;  ///< in the definition's order
};

/// The needle's predicted velocity ratio u_m / u0 for a record (see above);
/// 1 without a needle, above c = 0.3, or when the model finds no u_m.
double needle_velocity_ratio(double true_velocity, double void_fraction, double count_rate, double dx, double needle);

/// Resamples of the records for the ranking's stability.
constexpr int kBootstrapResamples = 200;

/// Scores and ranks every candidate from the rows (the definition's
/// objective and values), and says how often each ranks first when the
/// records of each condition are resampled with replacement
/// (kBootstrapResamples times, seeded by the design's seed: the same rows
/// give the same shares).
std::vector<RankedCandidate> rank_candidates(const DesignDefinition& d, const std::vector<DesignRow>& rows);

/// A column of the ranked CSV.
struct RankedColumn {
  std::string_view name;
  std::string_view unit;  ///< "-" for numbers without one, "text" for words
  std::string_view meaning;
};

/// The ranked CSV's columns in the order written: its header. The columns
/// before `condition` are the candidate's (the same on each of its rows), the
/// rest the condition's. The report (python/pdp/design_report.py) reads the
/// header as this declaration: it takes the split at `condition` and the
/// ranking (`ranking`, `values`) from the file, never guesses them.
std::span<const RankedColumn> ranked_columns();

/// The ranked CSV: one row per candidate and condition, best candidate first.
std::string ranked_csv(const std::vector<RankedCandidate>& ranked, const DesignDefinition& d);

/// The summary printed on stdout: the recommendation, its errors per
/// condition, and how much better it is than the worst and the current probe.
std::string design_summary(const std::vector<RankedCandidate>& ranked, const DesignDefinition& d,
                           const std::string& model_note);

}  // namespace study
