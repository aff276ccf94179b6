#pragma once
// Training the bias-correction model (METHOD.md 7) from pdp sweep CSVs:
// the training set, the held-out split, k-fold cross-validation of the
// hyperparameters, the held-out scores and the learning curve.
//
// Rows used: runs with no error whose AWCC gave a value from at least
// `min_windows` accepted windows; the others are counted by cause. A row's
// features come from its measured u, Tu, c and F, dx, dy and Np through the
// one feature contract (correction/features.hpp). The processing of the
// runs (columns awcc_filter_a ... awcc_subsample) must be the same in every
// row; it is recorded in the model. CSVs without those columns were written
// with the default processing, which is assumed and said.
// Held-out split: the rows ordered by a hash of (seed, study, run index); the first
// `held_out` fraction is held out. The model is trained on the rest only, so
// the held-out scores are those of the shipped model.
//
// Scores. Velocity: relative errors (a 1 m/s error at 2 m/s is not one at
// 40 m/s): RMSE of (u / u_true - 1) for raw AWCC and for the corrected
// median, and the pinball loss of the quantiles of u / u_true at the
// correction levels. Turbulence intensity: absolute (Tu is already relative):
// RMSE of Tu - Tu_true and the pinball loss of the quantiles. Coverage: the
// fraction of rows whose truth lies in [q0.1, q0.9] (nominal 80 %) and in
// [q0.025, q0.975] (nominal 95 %).
//
// The record's length saturates. The forests see every duration above that
// of the longest `duration_saturation_share` of their training runs as that
// one length (the cap), which is then the model's range maximum: a row
// beyond it is held there (model.hpp). Without the cap the longest record
// is a single run, and the trees' leaves at the range's end hold a few of
// the longest runs whatever else they are: a candidate trained on 20-300 s
// records corrected 300 s records at 500 kHz and low Tu by +30 % and +60 %
// (its three longest low-Tu runs were lag-quantised at 11-15 kHz), against
// +0.3 % at 295 s (docs/history/correction-foreign-conventions.md, "The first
// candidates: what the campaign's runs teach"). With the cap the edge holds
// 1 % of the runs, as long as one another in what the model learns from
// duration.
//
// Cross-validation: for each target, every (target form, min leaf, features
// per split) of the grid is scored by the mean pinball loss over k folds of
// the training rows; the least wins. Max depth stays unlimited: min leaf
// already bounds the trees, and leaves must hold enough rows for quantiles.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include <span>

#include "awcc/option_field.hpp"
#include "awcc/validation.hpp"
#include "correction/model.hpp"

namespace correction {

struct TrainingRow {
  std::uint64_t study = 0;              ///< sweep study id (several sweeps may be combined)
  std::int64_t run = 0;
  Features features;
  double true_velocity = 0.0, true_turbulence_intensity = 0.0;
  /// AWCC gave a usable velocity from at least min_windows accepted windows:
  /// the AWCC forests take the row. The FSCC forest is applied where this is
  /// false, so that is where it is calibrated and scored.
  bool awcc_served = true;
  /// The same run's features with AWCC's unweighted moments (the sweep's
  /// awcc_*_unweighted columns), for a model with the weighting feature.
  std::optional<Features> unweighted;
};

struct TrainingSet {
  std::vector<TrainingRow> rows;
  std::int64_t total = 0;               ///< rows read
  std::int64_t excluded_error = 0;      ///< the run failed (reason column)
  std::int64_t excluded_undefined = 0;  ///< AWCC gave no velocity
  std::int64_t excluded_windows = 0;    ///< fewer than min_windows accepted windows
  std::vector<std::string> sources;     ///< file names and study ids
  /// Runs with an FSCC velocity, bubbles, fs and duration, whatever AWCC gave
  /// (the FSCC forest's training set; not subject to min_windows).
  std::vector<TrainingRow> fscc_rows;
  Processing processing;                ///< how every run was processed
  bool processing_assumed = false;      ///< the CSVs do not say: the default was assumed
  /// The generator versions of the rows read (awcc::generator_version; 1 for
  /// sweeps without the column). More than one is allowed (the statistics
  /// are the same) but said: a warning and the model's provenance.
  std::set<int> generator_versions;
};

/// Which truth a run's row carries. pdp trains on the realised statistics of
/// the generated series (what the record holds); other simulators score
/// against the imposed parameters (the process the record samples). They
/// differ by the record's sampling error of the mean and the rms: u_rms
/// sqrt(2 T / D) for the mean of a record of D seconds with an integral
/// time scale T (about 0.6 % of u at Tu 0.25, T 0.1 s, 300 s).
enum class TruthKind { realised, imposed };
std::string_view to_string(TruthKind truth);
/// "realised" or "imposed"; empty otherwise.
std::optional<TruthKind> truth_kind_of(std::string_view text);

/// Reads sweep CSVs (pdp sweep's columns); throws InputError naming
/// the file, line and column when one is not such a CSV. A run index seen twice
/// (e.g. the same shard given twice) is refused. `truth`: the realised
/// truth columns (truth_velocity, truth_turbulence_intensity) or the scene's
/// imposed velocity and tu.
TrainingSet load_training_set(const std::vector<std::filesystem::path>& csvs, std::int64_t min_windows,
                              TruthKind truth = TruthKind::realised);

/// The share of a forest's training runs, the longest, whose durations it
/// sees as one (the header says why).
inline constexpr double duration_saturation_share = 0.01;

/// The duration above which `duration_saturation_share` of `rows` lie (their
/// durations' upper quantile; 0 when none is known).
double duration_cap(const std::vector<TrainingRow>& rows);

struct TrainOptions {
  int trees = 100;                      ///< trees per forest
  std::int64_t min_windows = 100;       ///< least accepted windows of a training run
  double held_out = 0.2;                ///< fraction of runs held out for the report
  int folds = 5;                        ///< cross-validation folds; 0 = no CV (use the values below)
  int cv_trees = 50;                    ///< trees per forest during cross-validation
  std::vector<int> min_leaf_grid{1, 2, 3, 5, 10, 20};
  std::vector<int> features_per_split_grid{2, 3, 5, 7};
  int min_leaf = 1;                     ///< without CV: the first of min_leaf_grid
  int features_per_split = 2;           ///< without CV: the first of features_per_split_grid
  TargetForm velocity_form = TargetForm::ratio;        ///< without CV
  TargetForm turbulence_form = TargetForm::difference; ///< without CV
  std::uint64_t seed = 1;
  int threads = 0;
  /// "measured" (the seven features of METHOD 7) or "extended" (also fs,
  /// duration and accepted windows: records of every length and rate), and
  /// their variants (feature_set_names: "+lag", "+weighting").
  std::string feature_set = "measured";
  /// With an extended feature set, also train the reduced model
  /// (CorrectionModel::reduced) for rows without the record's features.
  bool reduced = true;
  /// The FSCC forest's features: "fscc" or "fscc-2" (correction/features.hpp).
  std::string fscc_feature_set = "fscc";
  /// Fraction of the non-held-out runs set aside to calibrate the intervals
  /// (model.hpp, Calibration): the forests are trained on the rest. Without
  /// it the forest's intervals are as wide as its leaves make them, which
  /// was 3 points too wide for the 80 % interval of Tu.
  double calibration = 0.2;
  /// Accepted-window counts where the calibration bands meet: 10-30, 30-100, 100+.
  std::vector<std::int64_t> calibration_bands{30, 100};
  /// Values of the model's Tu where the calibration's Tu bands meet: the
  /// interval a run needs depends on how turbulent it is (a first model
  /// calibrated by windows alone covered 92 % of the u of its least
  /// turbulent runs and 63 % of its most turbulent at nominal 80 %).
  std::vector<double> calibration_tu_bands{0.1, 0.2, 0.3};
  [[nodiscard]] awcc::Validation validate() const;
};

/// The declarations of the training options (awcc/option_field.hpp): names,
/// help and defaults for the command line and settings files. The grids are
/// lists ("5,10,20"); without cross-validation their first values are used.
std::span<const awcc::OptionField<TrainOptions>> training_option_fields();

struct CvEntry {
  std::string target;                   ///< "velocity" | "turbulence_intensity"
  TargetForm form = TargetForm::value;
  int min_leaf = 0, features_per_split = 0;
  double pinball = 0.0;                 ///< mean over folds and rows
};

/// Scores of predictions against truth on some rows: every row the forests
/// give quantiles for, those the trust rules (model.hpp) leave untrusted
/// included (so that two models or two training sizes score the same rows).
struct HeldOutScores {
  std::int64_t rows = 0, out_of_range = 0;
  /// Of the scored rows, those the trust rules leave untrusted, and by rule
  /// (a row may break several).
  std::int64_t untrusted = 0, outside_envelope = 0, multimodal = 0, one_sample_lag = 0, chance_yield = 0;
  /// Of the scored rows, those whose Tu rule (e) holds back (any status);
  /// their Tu is scored with the others' (its quantiles).
  std::int64_t large_bubbles = 0;
  double velocity_rmse_raw = 0.0, velocity_rmse_corrected = 0.0;  ///< relative (u/u_true - 1)
  double velocity_bias_raw = 0.0, velocity_bias_corrected = 0.0;  ///< mean relative error
  double velocity_median_abs_raw = 0.0, velocity_median_abs_corrected = 0.0;  ///< median |relative error|
  double velocity_pinball = 0.0;        ///< relative
  double velocity_coverage80 = 0.0, velocity_coverage95 = 0.0;
  double tu_rmse_raw = 0.0, tu_rmse_corrected = 0.0;               ///< absolute
  double tu_bias_raw = 0.0, tu_bias_corrected = 0.0;
  double tu_median_abs_raw = 0.0, tu_median_abs_corrected = 0.0;  ///< median |error|
  double tu_pinball = 0.0;
  double tu_coverage80 = 0.0, tu_coverage95 = 0.0;
  std::vector<double> velocity_losses, tu_losses;  ///< pinball loss of each scored row, in row order
};

struct LearningPoint {
  std::int64_t training_rows = 0;
  HeldOutScores scores;
  /// Paired improvement of the mean pinball loss over the previous (smaller)
  /// point, on the same held-out rows, and its standard error (sd of the
  /// row differences / sqrt(rows)); 0 for the first point.
  double velocity_gain = 0.0, velocity_gain_se = 0.0, tu_gain = 0.0, tu_gain_se = 0.0;
};

struct HeldOutPrediction {
  TrainingRow row;
  Correction correction;
};

/// Held-out scores of the FSCC forest (velocity only, relative errors).
struct FsccScores {
  std::int64_t rows = 0, out_of_range = 0;
  std::int64_t untrusted = 0, outside_envelope = 0, multimodal = 0, one_sample_lag = 0;  ///< as HeldOutScores
  double rmse_raw = 0.0, rmse_corrected = 0.0;
  double median_abs_raw = 0.0, median_abs_corrected = 0.0;
  double coverage80 = 0.0, coverage95 = 0.0;
};

struct TrainResult {
  CorrectionModel model;
  std::int64_t training_rows = 0;
  /// Usable runs left out because they lack a feature of the set (a run
  /// without an FSCC velocity under "+fscc"): a row like them is not
  /// corrected by the AWCC forests either (missing_feature).
  std::int64_t excluded_features = 0;
  std::int64_t calibration_rows = 0;    ///< set aside to calibrate the intervals
  std::int64_t fscc_training_rows = 0;  ///< the FSCC forest's (extended feature set)
  FsccScores fscc_held_out;             ///< all held-out runs with an FSCC velocity
  FsccScores fscc_held_out_unserved;    ///< those AWCC cannot serve: where the forest is applied
  std::string fscc_calibration;         ///< which runs calibrated the FSCC forest's intervals
  std::string fscc_note;                ///< why there is no FSCC forest, when there is none
  std::vector<CvEntry> cv;              ///< every grid point scored
  int velocity_min_leaf = 0, velocity_features_per_split = 0;
  int turbulence_min_leaf = 0, turbulence_features_per_split = 0;
  HeldOutScores held_out;
  std::vector<HeldOutPrediction> predictions;
  /// The reduced model on the held-out runs with fs, duration and windows removed.
  HeldOutScores reduced_held_out;
  std::vector<HeldOutPrediction> reduced_predictions;
  std::vector<LearningPoint> learning_curve;  ///< nested training subsets 1/16, 1/8, 1/4, 1/2, 3/4, 1 of the training rows
  double seconds_cv = 0.0, seconds_train = 0.0;
  [[nodiscard]] std::string report() const;
};

/// Splits, cross-validates, trains and scores. `progress` gets a fraction done.
TrainResult train_model(const TrainingSet& set, const TrainOptions& options,
                        const std::function<void(double)>& progress = {});

/// A trained model with the envelopes of its trust rule (a) (model.hpp)
/// measured on runs it was not trained on, and how often the trust rules
/// fire on the held-out part of them.
struct TrustResult {
  CorrectionModel model;
  std::int64_t envelope_rows = 0, fscc_envelope_rows = 0;  ///< the runs that measured them
  HeldOutScores held_out;                 ///< the AWCC forests on the held-out runs
  FsccScores fscc_held_out_unserved;      ///< the FSCC forest on the held-out runs AWCC cannot serve
  std::string summary;                    ///< what was done and found (also appended to the provenance)
};

/// Measures a trained model's envelopes on `runs`: sweeps of its training
/// distribution with other seeds, so that no run was trained on (a model of
/// format 4 or older, which stores none, gains them so). The runs each
/// forest takes are split as train_model splits (options.held_out, seed);
/// the envelopes come from the rest, grouped as the model's calibration (the
/// FSCC forest's: from the runs AWCC cannot serve), and the rules are scored
/// on the held-out part. Throws awcc::InputError when the runs were processed
/// otherwise than the model's training data.
TrustResult measure_trust(CorrectionModel model, const TrainingSet& runs, const TrainOptions& options);

/// Throws awcc::InputError when the runs were processed otherwise than the
/// model's training data (its filter, ROC, weighting, signal, refinement):
/// a model scored or measured on them would describe other estimates.
void require_model_processing(const CorrectionModel& model, const TrainingSet& runs);

/// The rows as a peer's file states them (pdp-uq's layout: u, u_rms, c,
/// d32, dx, dy, Np): fs, the duration, the windows and the time-scale ratio
/// removed, so that a model corrects them by its reduced forest.
std::vector<TrainingRow> as_peer_rows(std::vector<TrainingRow> rows);

/// Scores a model on rows.
HeldOutScores score(const CorrectionModel& model, const std::vector<TrainingRow>& rows,
                    std::vector<HeldOutPrediction>* predictions = nullptr, int threads = 0);

/// The two forests and the ranges from training rows.
CorrectionModel fit_model(const std::vector<TrainingRow>& rows, TargetForm velocity_form,
                                TargetForm turbulence_form, const ForestOptions& velocity_options,
                                const ForestOptions& turbulence_options, std::int64_t min_windows,
                                const std::vector<std::string>& names = feature_set_names("measured"));

/// The calibration of a model's intervals on runs its forests were not
/// trained on (model.hpp), and the envelopes of its trust rule (a): per
/// group with at least 399 runs, else the window band's, else pooled, else
/// the model's own (its training targets').
Calibration calibrate(const CorrectionModel& model, const std::vector<TrainingRow>& rows,
                      const std::vector<std::int64_t>& window_edges, int threads = 0,
                      const std::vector<double>& tu_edges = {});

/// Scores of held-out predictions in one band of runs: errors of the raw and
/// the corrected values (velocity relative, Tu absolute) and the coverage of
/// the 80 % and 95 % intervals, over the rows the model corrected.
struct BandScores {
  std::string band;  ///< "all", "true Tu 0.1-0.2", "windows 30-99", "fs 50-200 kHz", ...
  std::int64_t runs = 0;  ///< held-out runs in the band
  std::int64_t rows = 0;  ///< of which corrected (the scores are over these)
  double velocity_rmse_raw = 0.0, velocity_rmse_corrected = 0.0;
  double velocity_median_abs_raw = 0.0, velocity_median_abs_corrected = 0.0;
  double tu_rmse_raw = 0.0, tu_rmse_corrected = 0.0;
  double tu_median_abs_raw = 0.0, tu_median_abs_corrected = 0.0;
  double velocity80 = 0.0, velocity95 = 0.0, tu80 = 0.0, tu95 = 0.0;
};
/// The scores of held-out predictions: all runs, by band of the true Tu
/// (0-0.1, 0.1-0.2, 0.2-0.3, 0.3-0.35, 0.35-0.45), of the model's corrected
/// Tu (0-0.1, 0.1-0.2, 0.2-0.3, 0.3+), of accepted windows (10-29, 30-99,
/// 100+) and of fs (up to 50 kHz, 50-200 kHz, above); bands without a
/// corrected row are left out.
std::vector<BandScores> scores_by_band(const std::vector<HeldOutPrediction>& predictions);

/// The scores as the training report prints them: raw and corrected errors,
/// coverage, and the table of scores_by_band.
std::string scores_report(const HeldOutScores& scores, const std::vector<HeldOutPrediction>& predictions);

/// The rows of `predictions` that `other` also corrected (the same runs in
/// the same order): to score two models on the runs both correct.
std::vector<HeldOutPrediction> corrected_by_both(const std::vector<HeldOutPrediction>& predictions,
                                                 const std::vector<HeldOutPrediction>& other);

/// A second model (e.g. the one shipped before) on the same held-out runs,
/// band by band (not by the model's Tu: each model has its own): how many
/// runs each corrects, and the errors and coverage of both on the runs both
/// correct.
std::string comparison_report(const std::vector<HeldOutPrediction>& mine, const std::vector<HeldOutPrediction>& other,
                              const std::string& other_name);

/// Held-out predictions as CSV: run, features, truth, in_range (1: corrected), status
/// (corrected, untrusted, ...), the quantiles (of untrusted rows too).
std::string predictions_csv(const std::vector<HeldOutPrediction>& predictions);
/// The learning curve as CSV.
std::string learning_curve_csv(const std::vector<LearningPoint>& curve);

}  // namespace correction
