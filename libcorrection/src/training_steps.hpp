#pragma once
// The steps the training's parts share (private to libcorrection): feature
// building (training_data.cpp), the split of the runs (campaign.cpp), the
// calibration's scores (calibration.cpp) and the FSCC forest's scores
// (scoring.cpp). training.cpp fits with them; nothing outside the library
// sees them.

#include <array>
#include <chrono>
#include <vector>

#include "awcc/csv.hpp"
#include "awcc/parallel.hpp"
#include "awcc/random.hpp"
#include "correction/model.hpp"
#include "correction/training.hpp"

namespace correction::detail {

using awcc::cell_number;
using awcc::mix64;
using awcc::parallel_for;
using awcc::split_cells;

double seconds_since(std::chrono::steady_clock::time_point start);

// --- Feature building (training_data.cpp) ---
/// The model's quantile levels (correction_levels) as a vector.
std::vector<double> levels();
std::vector<std::string> names_of(const std::vector<FeatureRange>& ranges);
/// A training row's feature vector in the order of `names`; throws
/// OptionError naming a feature the row lacks.
std::vector<double> vector_of(const Features& f, const std::vector<std::string>& names);
/// The rows' features and targets (velocity or Tu, in `form`) for a forest.
TrainingData data_of(const std::vector<TrainingRow>& rows, bool velocity, TargetForm form,
                     const std::vector<std::string>& names);
/// Pinball loss of one target's quantiles (velocity relative to the truth, Tu absolute).
double target_pinball(const std::vector<double>& q, const TrainingRow& r, bool velocity);
/// A forest's quantiles of a row, back in the quantity's units.
std::vector<double> predict(const QuantileForest& f, TargetForm form, const TrainingRow& r, bool velocity,
                            const std::vector<std::string>& names);

// --- The split of the runs (campaign.cpp) ---
/// The runs' split: held out first, then the calibration runs, then the
/// training runs, in the order of a hash of the run (independent of file order).
struct Split {
  std::vector<TrainingRow> held_out, calibration, training;
};
/// The rows as the forests see them: durations above the cap at the cap.
std::vector<TrainingRow> with_saturated_durations(std::vector<TrainingRow> rows);
Split split_runs(std::vector<TrainingRow> rows, const TrainOptions& o);
/// The rows and, after each that has one, its unweighted twin.
std::vector<TrainingRow> with_unweighted_twins(const std::vector<TrainingRow>& rows);

// --- Calibration's scores (calibration.cpp) ---
/// The intervals' miscoverage, 1 - interval_coverages (model.hpp).
inline constexpr IntervalOffsets calibration_alpha{0.5, 0.2, 0.1, 0.05};
/// Q = E_k, k = ceil((n + 1)(1 - alpha)) of the scores (model.hpp,
/// Calibration); infinity-needing k > n is refused.
double conformal_offset(std::vector<double> e, double alpha);
/// A row's conformity scores for the intervals of a forest's quantiles t at
/// correction_levels: max(lower - target, target - upper) of each.
IntervalOffsets interval_scores(const std::vector<double>& t, double target);
/// The envelopes of trust rule (a) from rows' shifts {velocity, Tu} and their groups.
void set_envelopes(Calibration& c, const CorrectionModel& model, const std::vector<int>& band,
                   const std::vector<int>& tu_band, const std::vector<std::array<double, 2>>& shifts);
/// The FSCC forest's envelope from rows' truths.
std::vector<std::array<double, 2>> fscc_envelope(const FsccForest& f, const std::vector<TrainingRow>& rows);

// --- Scores (scoring.cpp) ---
/// The FSCC forest's scores on held-out rows (all with an FSCC velocity, or
/// only those AWCC cannot serve: where the forest is applied).
FsccScores score_fscc(const CorrectionModel& scorer, const std::vector<TrainingRow>& held_out, bool unserved_only);

}  // namespace correction::detail
