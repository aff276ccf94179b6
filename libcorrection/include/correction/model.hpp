#pragma once
// Bias correction with uncertainty, METHOD.md 7: two quantile regression
// forests (correction/quantile_forest.hpp) map what AWCC measured (the
// features of correction/features.hpp) to the distribution of the truth.
//
// Targets: the true mean velocity and the true Tu, each learnt in the form
// the model names (TargetForm) and mapped back:
//   value       t = y_true                  y_q = t_q
//   ratio       t = y_true / y_measured     y_q = y_measured t_q   (y_measured > 0)
//   difference  t = y_true - y_measured     y_q = y_measured + t_q
// Each map is increasing in t, so quantiles of t give quantiles of y_true.
// Turbulence intensities are not negative: their quantiles are clipped at 0,
// which is the quantile of the clipped distribution.
//
// A row is corrected only inside the training data: every feature within its
// training [min, max] widened by `range_margin` on each side (the trees split
// between training values, so beyond the data they repeat the edge leaf:
// that is extrapolation; accepted_range owns the rule), and at least `min_windows` accepted
// windows (runs with fewer were left out of training). Otherwise the row
// keeps its measurement, with a status and the reason. A model is applied
// only to results processed as its training data were (`processing`).
//
// One feature is held instead of refused: a record longer than the longest
// training record is corrected as one of that length, with a note. A longer
// record holds more of the same signal: its measurement is closer to the
// long-record value than the training records' were, so the spread the
// model learnt at its longest records bounds the longer one's from above
// (docs/validation.md measures it on 600-1800 s records). No other feature
// is monotone so: beyond the training data of u, Tu, c, d32, dx, dy, Np, fs,
// the windows or the yield the biases change (METHOD 6), and a row there is
// refused as outside_training_range; a record shorter than the shortest
// is too (it holds less than any training record did).
//
// Trust rules. A corrected value outside the envelope its inputs allow is
// not reported as corrected (status untrusted, the reason naming the rule
// and its numbers; the quantiles are kept so that a report can draw them
// apart):
// (a) envelope: the median's shift from the measurement, s = t_median -
//     t(measured) in target units (t(measured) is 1 for a ratio, 0 for a
//     difference), must lie within [-below, above], the range that held the
//     truth's shift t_true - t(measured) for envelope_coverage of the runs
//     of the row's group (as for the calibration) that the forests were not
//     trained on (the calibration runs; for the FSCC forest, those AWCC
//     cannot serve). A median farther from the measurement than the truth
//     lay for all but 0.25 % of such runs on that side is beyond the
//     envelope the inputs allow. Models of format 4 and older store no
//     envelope (nor do forests trained without calibration runs): it is
//     taken from the forest's training targets, the same shifts on its
//     training runs (the measurement's error does not depend on whether a
//     run was trained on), pooled over the groups since the targets carry
//     no features; `pdp train --envelope-of` measures a group's on fresh runs.
// (b) one mode: the forest's predictive distribution (before calibration)
//     must not dip (correction/modality.hpp) below multimodal_dip_limit.
// (c) a resolved lag: the measurement's lag in samples, dx fs / u (AWCC's
//     velocity for the AWCC forests, FSCC's for the FSCC forest), must be
//     at least awcc::least_resolved_lag_samples (1.5). Below it the delay
//     reads as one sample whatever it was (0.5-1.5 samples), so the record
//     bounds the velocity (dx fs / 1.5 to dx fs / 0.5) and no forest's
//     median is a measurement of it: the forest can only return where such
//     records' truths lay in its training runs (0.63-3.0 times the reading
//     for 95 % of the campaign's), which says nothing of this flow's. Rule
//     (a) does not catch it once the calibration runs hold such records
//     (their shifts widen the envelope). A row without fs (a peer's) has
//     no lag in samples and is not judged by it.
// (d) a yield above chance (the AWCC forests): the data yield, accepted
//     over formed windows, must be at least awcc::chance_data_yield (0.1 %).
//     Signals that share no bubble pass AWCC's filter in 0.03-0.08 % of
//     their windows, so below it the accepted windows may be chance peaks,
//     and the measurement the forest corrects may not be the flow's (raw
//     AWCC off by a median 58 % there on the campaign's runs, corrected by
//     20 %, its 95 % intervals covering 90 %). A row whose
//     windows are not known (a peer's) is not judged by it.
// Any rule, on the velocity or on Tu, makes the row untrusted.
// (e) Tu of tips far closer than the bubbles (the AWCC forests' Tu only):
//     the measured d32 / dx must be at most largest_tu_size_ratio (10).
//     Tips a tenth of a bubble apart meet each interface almost together,
//     so a window's delay follows the interface's tilt more than the flow
//     and AWCC's Tu reads high by an amount no feature carries (the ratio
//     itself, as a feature, took a sixth of it). On the conventions
//     campaign's corrected test rows the corrected Tu's mean error is
//     -0.001 to -0.004 and its 80 % intervals cover 86-89 % in every band
//     of d32 / dx up to 10; above it +0.011 (10-14), +0.023 (14-20) and
//     +0.06-0.07 (beyond 20), covering 61-80 % (docs/validation.md). Such
//     a row's Tu is not corrected (its median not reported, its quantiles
//     kept, Correction::turbulence_message says why); its velocity, whose
//     error there is 2-4 % with intervals that hold, stands. A row without
//     d32 or dx is not judged by it.
//
// Model file (".qrf"), all numbers little-endian whatever the machine:
//   "pdp-qrf\n" (8 bytes), u32 format version, u64 payload bytes, payload,
//   u32 CRC-32 (IEEE 802.3) of everything before it.
// Payload: provenance text; features (name, min, max); range margin; minimum
// windows; [version 2: the processing: f64 filter A, u8 robust outlier cutoff,
// u8 weighting (0 duration, 1 none), u8 signal (0 binary, 1 raw), u8 peak
// refinement (0 none, 1 parabolic)]; per forest its name, target form,
// feature count, training targets (f64), tree count, the width of a held row
// (u8: 2 or 4 bytes; 2 when there are at most 65,536 targets) and the trees:
// node count, nodes (a split: u8 feature, f64 threshold, u32 left child, the
// right child being left + 1; a leaf: u8 0xff, u32 first held row, u32
// count), held-row count (u64), held rows. Version 1 files (no processing)
// were all trained with the default processing, which they are read with.
// Version 3 stores each forest as its block (correction/quantile_forest.hpp:
// fixed 12-byte nodes, read in place from the file's bytes, nothing built):
// name, u8 target form, u64 block bytes, the block. It admits the extended feature set (the seven measured features,
// then fs, duration and windows_accepted: see correction/features.hpp;
// versions 1 and 2 have the seven only) and, after the processing, the
// calibration: u32 band count B (0: none), B - 1 window edges (i64), [version
// 4: u32 Tu band count T, T - 1 Tu edges (f64); version 3: T = 1], then
// B x T x 3 offsets (f64) for the velocity and B x T x 3 for Tu; after the two
// forests, u32 0 or 1, then the FSCC forest: its feature ranges (count, then
// name, min, max), its calibration (u32 0 or 1, then 3 offsets), [version 5:
// its envelope (u32 0 or 1, then below, above)] and the forest
// ("fscc_velocity"). Version 5 adds, after the calibration offsets, the
// envelopes of rule (a): u32 E (0: none, 1: pooled, or B x T: per group),
// then E x 2 values (below, above) for the velocity and E x 2 for Tu.
// Version 7 stores 4 offsets wherever earlier versions store 3 (the 50, 80,
// 90 and 95 % intervals of the nine reported levels, against 50, 80, 95 %).
// A file that is not a model, of a newer version, truncated or damaged is
// refused with a message naming the file and the fix.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/serialise.hpp"
#include "correction/features.hpp"
#include "correction/quantile_forest.hpp"

namespace correction {

/// The quantile levels every correction reports: pdp-uq's nine (issue 51).
/// Pairs symmetric about the median bound the central intervals of
/// interval_coverages.
inline constexpr std::array<double, 9> correction_levels{0.025, 0.05, 0.1, 0.25, 0.5, 0.75, 0.9, 0.95, 0.975};
/// Their JSON keys and CSV suffixes.
inline constexpr std::array<const char*, 9> correction_level_names{"0.025", "0.05", "0.1",  "0.25", "0.5",
                                                                   "0.75",  "0.9",  "0.95", "0.975"};
/// The median's index in correction_levels.
inline constexpr std::size_t median_level = 4;
/// The central intervals, narrowest first: interval k runs from the level
/// lower_level(k) to upper_level(k).
inline constexpr std::array<double, 4> interval_coverages{0.5, 0.8, 0.9, 0.95};
inline constexpr std::size_t interval_count = interval_coverages.size();
inline constexpr std::size_t interval80 = 1, interval90 = 2, interval95 = 3;
constexpr std::size_t lower_level(std::size_t interval) { return median_level - 1 - interval; }
constexpr std::size_t upper_level(std::size_t interval) { return median_level + 1 + interval; }
static_assert(2 * interval_count + 1 == correction_levels.size());
/// A conformal offset per central interval (Calibration), in target units.
using IntervalOffsets = std::array<double, interval_count>;

/// The keys of a correction as to_json(Correction) writes it that are read
/// back (a profile's flow reads the corrected velocity), and the key of a
/// process JSON's row that holds it.
namespace correction_key {
inline constexpr std::string_view correction = "correction";
inline constexpr std::string_view status = "status";
inline constexpr std::string_view forest = "forest";
inline constexpr std::string_view velocity = "velocity";
inline constexpr std::string_view quantiles = "quantiles";  ///< by correction_level_names
inline constexpr std::string_view turbulence_intensity = "turbulence_intensity";
/// In turbulence_intensity: why its median is null on a row whose velocity
/// stands (rule (e)), null otherwise.
inline constexpr std::string_view reason = "reason";
}  // namespace correction_key
/// The correction's CSV columns read back (correction_csv_columns declares them).
namespace correction_column {
inline constexpr std::string_view status = "correction_status";
inline constexpr std::string_view forest = "correction_forest";
/// Followed by a level's name: the velocity's quantile at that level.
inline constexpr std::string_view velocity_quantile = "corrected_velocity_q";
/// Why the corrected Tu is empty on a row whose velocity stands (rule (e)).
inline constexpr std::string_view turbulence_reason = "correction_turbulence_reason";
}  // namespace correction_column

enum class TargetForm : std::uint8_t { value = 0, ratio = 1, difference = 2 };
std::string_view to_string(TargetForm f);

struct FeatureRange {
  std::string name;
  double min = 0.0, max = 0.0;
};

/// The values of a feature a model corrects: its training [min, max]
/// widened by `margin` of the span on each side, except at the low end of a
/// feature on a logarithmic scale (Features::on_log_scale: c, u, d32, fs,
/// ...), which is widened by `margin` of the span of its logarithm,
/// min * (max / min)^-margin. A linear margin of such a range reaches far
/// below the least training value (1 % of c = 0.005-0.6 is 0.006, the
/// whole lower decade and more), where the biases differ (METHOD 6); the
/// logarithmic one is a few per cent of the value. (At the high end the
/// linear margin is the narrower, and is kept.)
FeatureRange accepted_range(const FeatureRange& training, double margin);

struct CorrectedQuantity {
  double measured = 0.0;
  std::array<double, correction_levels.size()> quantiles{};  ///< at correction_levels
  [[nodiscard]] double median() const { return quantiles[median_level]; }
  /// The bounds of central interval k (interval80, interval95, ...).
  [[nodiscard]] double lower(std::size_t interval) const { return quantiles[lower_level(interval)]; }
  [[nodiscard]] double upper(std::size_t interval) const { return quantiles[upper_level(interval)]; }
};

/// The correction of one row: a value with a status.
struct Correction {
  CorrectionStatus status = CorrectionStatus::awcc_not_run;
  std::string message;                ///< why not corrected (empty when corrected)
  /// The forest's quantiles: of a corrected row, or of an untrusted one
  /// (which are not a corrected value: the report draws them apart).
  std::optional<CorrectedQuantity> velocity, turbulence_intensity;
  /// Which forest gave the quantiles: "awcc", "awcc-reduced" (a row without
  /// the record's features, CorrectionModel::reduced), or "fscc" (the
  /// velocity only: Tu stays uncorrected); empty when there are none.
  std::string forest;
  /// What the user should know of a correction that stands (a feature held
  /// at its range's end), each said once.
  std::vector<std::string> notes;
  /// Which trust rules an untrusted row breaks: (a)-(d) of the model's header.
  bool outside_envelope = false, multimodal = false, one_sample_lag = false, chance_yield = false;
  /// Rule (e) of the model's header: bubbles far larger than the tip
  /// separation, so that Tu is not corrected whatever the velocity's status;
  /// `turbulence_message` says why (empty when the rule holds).
  bool large_bubbles = false;
  std::string turbulence_message;
  [[nodiscard]] bool corrected() const { return status == CorrectionStatus::corrected; }
  /// The row is corrected and its Tu too (not an FSCC forest's row, rule (e) holds).
  [[nodiscard]] bool turbulence_corrected() const {
    return corrected() && turbulence_intensity.has_value() && !large_bubbles;
  }
  /// Empty when corrected; "untrusted: " and the reason, or the reason.
  [[nodiscard]] std::string why_not() const;
};

/// The limit of rule (b) (the trust rules above): a predictive distribution
/// whose dip ratio (correction/modality.hpp) is below it is multimodal. A
/// unimodal density has a ratio of at least 1; a forest's weighted sample
/// of one falls below 1 by chance. Of 3,000 runs the shipped model was not
/// trained on, 0.6 % of the AWCC forest's velocity distributions, none of
/// its Tu ones and 1.9 % of the FSCC forest's fell below 0.4, their medians
/// off by 1.8-2.8 times the others' (docs/validation.md); the 2 mm row of the
/// real profile (issue 29) is at 0.31.
inline constexpr double multimodal_dip_limit = 0.4;
/// The limit of rule (e) (the trust rules above): above this measured
/// d32 / dx the AWCC forests' Tu is not corrected. The bands of d32 / dx
/// measured in docs/validation.md change behaviour between 7-10 (Tu mean
/// error -0.001, 80 % coverage 89 %) and 10-14 (+0.011, 69 %).
inline constexpr double largest_tu_size_ratio = 10.0;
/// The share of the calibration runs' truths the envelope of rule (a) holds:
/// a median beyond it is farther from the measurement than all but 0.25 % of
/// the truths on that side. At 99 % the rule fired on 1.9 % of held-out runs,
/// most of them rows where the forest was right to move far (AWCC at 10-25
/// kHz, a lag of one or two samples); at 99.5 % on 0.7 %, whose medians were
/// off by 4 times the others' (docs/validation.md).
inline constexpr double envelope_coverage = 0.995;

/// A row that is not corrected, with the status and reason.
Correction not_corrected(CorrectionStatus status, std::string message);

/// Calibrated intervals: split conformalised quantile regression (Romano,
/// Patterson and Candes 2019), by group. On calibration runs the forests
/// were not trained on, a run's score for the interval [q_lo, q_hi] of its
/// target t (in the forest's target form) is E = max(q_lo - t, t - q_hi).
/// With the scores E_1 <= ... <= E_n of the run's group, the interval
/// [q_lo - Q, q_hi + Q] with Q = E_k, k = ceil((n + 1)(1 - alpha)), covers
/// a new run of the same distribution with probability at least 1 - alpha
/// (and at most 1 - alpha + 1/(n + 1)); Q < 0 narrows an interval that was
/// too wide. Intervals: the central 50 %, 80 % and 95 % of the reported
/// levels; the median is left as the forest gives it. Groups are bands of
/// accepted windows (the feature that most changes how wide an interval
/// must be) crossed with bands of the Tu forest's uncalibrated median (how
/// turbulent the model reads the flow: a function of the features only, so
/// the guarantee holds within each group, and the intervals of u and Tu are
/// as wide as each range of Tu needs). A group with fewer than 50
/// calibration runs takes its window band's offsets, and a window band with
/// fewer, the pooled ones. A row whose windows are unknown takes each
/// interval's widest window band at its Tu band.
struct Calibration {
  /// Band g holds windows in [edges[g - 1], edges[g]) (band 0 from 0, the last to infinity).
  std::vector<std::int64_t> window_edges;
  /// Tu band h holds the Tu forest's median in [edges[h - 1], edges[h]);
  /// empty: one Tu band (format 3 files).
  std::vector<double> tu_edges;
  /// Per group (window band w, Tu band h at w x (tu_edges.size() + 1) + h):
  /// Q of the intervals of interval_coverages (50, 80, 90, 95 %), in
  /// target units. A model of format 6 or older has no 90 % offset; it is
  /// read as the 80 and 95 % offsets' interpolation in the normal score
  /// (model_file.cpp), not a conformal one.
  std::vector<IntervalOffsets> velocity, turbulence_intensity;
  /// The envelopes of rule (a) (the trust rules above): {below, above}, the
  /// truth's shift from the measurement held by envelope_coverage of the
  /// runs, in target units; per group, one pooled, or none.
  std::vector<std::array<double, 2>> velocity_envelope, turbulence_envelope;
  /// The envelopes were taken from the forests' training targets (a model of
  /// format 4 or older), not from runs the forests were not trained on.
  bool envelope_from_training = false;
  [[nodiscard]] bool empty() const { return velocity.empty(); }
  /// The window band of a row (-1 when its windows are not known).
  [[nodiscard]] int band(std::int64_t windows) const;
  /// The Tu band of a median.
  [[nodiscard]] int tu_band(double tu_median) const;
  [[nodiscard]] std::size_t tu_bands() const { return tu_edges.size() + 1; }
  /// The offsets of a row: its group's, or with unknown windows each
  /// interval's widest over the window bands at its Tu band.
  [[nodiscard]] IntervalOffsets offsets(const std::vector<IntervalOffsets>& groups, std::int64_t windows,
                                        double tu_median) const;
  /// The envelope of a row the same way (the pooled one when there is one);
  /// empty when there is none.
  [[nodiscard]] std::optional<std::array<double, 2>> envelope(const std::vector<std::array<double, 2>>& groups,
                                                              std::int64_t windows, double tu_median) const;
  /// "windows 30-99, model Tu 0.1-0.2": the group of a row, in words.
  [[nodiscard]] std::string group_text(std::int64_t windows, double tu_median) const;
  /// Applies the offsets of `band` to the quantiles t at correction_levels
  /// (target units), keeping them in order.
  static void apply(const IntervalOffsets& offsets, std::vector<double>& t);
};

/// The second forest of an extended model: the mean velocity from FSCC's
/// (features "fscc" of correction/features.hpp), for rows without a usable
/// AWCC result. Its calibration has one band (velocity offsets only).
struct FsccForest {
  std::vector<FeatureRange> ranges;
  TargetForm form = TargetForm::ratio;
  QuantileForest velocity;
  Calibration calibration;
};

struct CorrectionModel {
  static constexpr std::uint32_t format_version = 7;

  std::string provenance;             ///< how the model was made (sweep, rows, options, held-out scores)
  std::vector<FeatureRange> ranges;   ///< training data [min, max] per feature, feature order
  double range_margin = 0.01;         ///< fraction of each span added on both sides
  std::int64_t min_windows = 100;     ///< least accepted windows of a corrected row
  Processing processing;              ///< how the training data were processed
  TargetForm velocity_form = TargetForm::ratio;
  TargetForm turbulence_form = TargetForm::difference;
  QuantileForest velocity, turbulence_intensity;
  Calibration calibration;            ///< empty: the forests' quantiles as they are (format 1, 2)
  std::optional<FsccForest> fscc;     ///< the FSCC forest (format 3, when trained)
  /// Peers' rows (issue 33): a model of the measured features only (u, Tu,
  /// c, d32, dx, dy, Np), trained on the same runs over the whole range of
  /// the record's features, for rows that do not state fs, the duration or
  /// the windows (pdp-uq's CSV, Kramer's toolbox). Its intervals are
  /// calibrated pooled over the records it stands for, so they are wider
  /// than the extended model's for a record it knows. The correction names
  /// it: forest "awcc-reduced". Format 6, extended models.
  std::shared_ptr<const CorrectionModel> reduced;

  /// Corrected, or too few windows / outside the training range, with the reason.
  [[nodiscard]] Correction correct(const Features& f) const;
  /// From a measurement: its features (make_features) or why there are none.
  /// Rows AWCC cannot correct (no usable AWCC velocity, low quality, too few
  /// windows, outside the AWCC forest's ranges) get the FSCC forest's
  /// velocity where the model has one and FSCC gave a velocity.
  [[nodiscard]] Correction correct(const Measurement& m) const;
  /// From a processed recording's measurement (measurement_of): its AWCC
  /// status decides whether AWCC's forest may be asked.
  [[nodiscard]] Correction correct(const MeasurementResult& m) const;
  /// The FSCC forest alone (not_corrected when the model has none).
  [[nodiscard]] Correction correct_fscc(const Features& f) const;
  /// Where a forest has no envelope (format 4 files, forests trained
  /// without calibration runs): its training targets' (the trust rules).
  void use_training_envelopes();
  /// True when the model has an FSCC forest and a row with this AWCC status may go to it.
  [[nodiscard]] bool falls_back_to_fscc(CorrectionStatus awcc_status) const;

  /// True when the AWCC weighting is one of the features (a "+weighting"
  /// set): results of either weighting are corrected, each as its own.
  [[nodiscard]] bool takes_weighting() const;
  /// The weighting feature's place in `ranges` (ranges.size() when there is none).
  [[nodiscard]] std::size_t weighting_feature() const;
  /// Empty when results processed this way may be corrected, else the
  /// differences ("filter A: model 0.4, results 0.3"); a model that takes the
  /// weighting as a feature corrects either.
  [[nodiscard]] std::string mismatch(const Processing& results) const;

  [[nodiscard]] std::vector<std::uint8_t> serialise() const;
  /// `name` is used in messages only. Throws awcc::InputError.
  static CorrectionModel parse(const std::vector<std::uint8_t>& bytes, const std::string& name);
  /// The same from bytes that `owner` keeps alive: format 3 forests are read
  /// in place, nothing is built.
  static CorrectionModel parse(std::shared_ptr<const void> owner, std::span<const std::uint8_t> bytes,
                               const std::string& name);
  /// Written to a temporary name and renamed when complete.
  void save(const std::filesystem::path& path) const;
  /// Throws awcc::InputError naming the file, the problem and the fix.
  static CorrectionModel load(const std::filesystem::path& path);
};

/// The forest target of a truth given the measurement, and back.
double to_target(TargetForm form, double truth, double measured);
double from_target(TargetForm form, double target, double measured);

/// Profile CSV columns of a correction (no leading comma): correction_in_range,
/// correction_reason, correction_forest, corrected_velocity (median; empty
/// unless corrected), corrected_velocity_q0.025 .. _q0.975 (of untrusted rows
/// too), the same for turbulence_intensity (its median empty too where rule
/// (e) holds it back), correction_status, correction_notes and
/// correction_turbulence_reason.
std::string correction_csv_header();
/// The same columns declared as the profile CSV's (awcc::ProfileColumn).
std::span<const awcc::ProfileColumn> correction_csv_columns();
std::string correction_csv_cells(const Correction& c);
/// The velocity's and Tu's cells of a row, each with a leading comma: the
/// median (empty unless corrected; Tu's also when rule (e) holds it back)
/// and the seven quantiles, or empty cells.
std::string quantile_cells(const Correction& c);
/// The notes joined by "; " (one CSV cell).
std::string notes_text(const Correction& c);

/// {"status", "in_range", "forest", "reason", "notes": [...], "velocity": {"measured", "median" (null unless
/// corrected), "quantiles": {"0.025": ...}}, "turbulence_intensity": ...}
nlohmann::json to_json(const Correction& c);

/// The envelope {below, above} of shifts (target units) holding
/// `coverage` of them, by the conformal rank: above = the k-th smallest
/// shift with k = ceil((n + 1)(1 + coverage) / 2), below = minus the k-th
/// largest; each holds a new run of the same distribution with probability
/// at least (1 + coverage) / 2. Both are at least 0 (the envelope holds the
/// measurement: rule (a) bounds how far a median moves, not how near it
/// stays). Empty when n is too small for the rank (n < 2 / (1 - coverage) -
/// 1: 399 runs at 99.5 %).
std::optional<std::array<double, 2>> envelope_of(std::vector<double> shifts, double coverage = envelope_coverage);

/// The model file's checksum: CRC-32 (IEEE 802.3, reflected), zlib's.
std::uint32_t crc32(const std::uint8_t* data, std::size_t size);

}  // namespace correction
