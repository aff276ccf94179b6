// Fitting: the forests, their hyperparameters by cross-validation, the
// learning curve, the FSCC and reduced forests, a model's provenance, and
// the trust measured on held-out runs.

#include "correction/training.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <thread>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/order_statistics.hpp"
#include "awcc/parallel.hpp"
#include "awcc/random.hpp"
#include "awcc/units.hpp"
#include "awcc/version.hpp"
#include "correction/sweep_columns.hpp"
#include "training_steps.hpp"

namespace correction {

using namespace detail;

CorrectionModel fit_model(const std::vector<TrainingRow>& rows, TargetForm velocity_form,
                                TargetForm turbulence_form, const ForestOptions& velocity_options,
                                const ForestOptions& turbulence_options, std::int64_t min_windows,
                                const std::vector<std::string>& names) {
  CorrectionModel m;
  m.min_windows = min_windows;
  m.velocity_form = velocity_form;
  m.turbulence_form = turbulence_form;
  for (const auto& n : names) m.ranges.push_back({n, 1e300, -1e300});
  for (const auto& row : rows) {
    const auto x = vector_of(row.features, names);  // names a missing feature
    for (std::size_t j = 0; j < names.size(); ++j) {
      m.ranges[j].min = std::min(m.ranges[j].min, x[j]);
      m.ranges[j].max = std::max(m.ranges[j].max, x[j]);
    }
  }
  m.velocity = QuantileForest::train(data_of(rows, true, velocity_form, names), velocity_options);
  m.turbulence_intensity = QuantileForest::train(data_of(rows, false, turbulence_form, names), turbulence_options);
  m.use_training_envelopes();
  return m;
}

namespace {

// The FSCC forest (model.hpp, FsccForest) on its own rows: the same held-out
// and calibration fractions and split key as the AWCC forests, the velocity
// forest's settings, target u_true / u_FSCC.
void train_fscc(const TrainingSet& set, const TrainOptions& o, const ForestOptions& velocity_options,
                TrainResult& result) {
  if (set.fscc_rows.size() < 500) {
    result.fscc_note = fmt::format("no FSCC forest: {} runs with an FSCC velocity, fewer than 500", set.fscc_rows.size());
    return;
  }
  // Named references, not a structured binding: the lambdas below use them
  // (clang 14, which builds the fuzz targets, cannot capture a binding).
  const Split split = split_runs(set.fscc_rows, o);
  const auto& held_out = split.held_out;
  const auto& calibration_rows = split.calibration;
  const auto training = with_saturated_durations(split.training);
  const auto names = feature_set_names(o.fscc_feature_set);
  FsccForest f;
  f.form = TargetForm::ratio;
  for (const auto& n : names) f.ranges.push_back({n, 1e300, -1e300});
  for (const auto& row : training) {
    const auto x = vector_of(row.features, names);
    for (std::size_t j = 0; j < names.size(); ++j) {
      f.ranges[j].min = std::min(f.ranges[j].min, x[j]);
      f.ranges[j].max = std::max(f.ranges[j].max, x[j]);
    }
  }
  TrainingData d;
  d.features = static_cast<int>(names.size());
  for (const auto& r : training) {
    const auto x = vector_of(r.features, names);
    d.x.insert(d.x.end(), x.begin(), x.end());
    d.y.push_back(to_target(f.form, r.true_velocity, r.features.fscc_velocity));
  }
  ForestOptions fo = velocity_options;
  fo.features_per_split = std::min(fo.features_per_split, d.features);
  f.velocity = QuantileForest::train(d, fo);
  // Calibrated where it is applied: on the calibration runs AWCC cannot
  // serve (few bubbles or windows, short records), whose FSCC errors differ
  // from those of the well-served runs; on all calibration runs when there
  // are too few of those.
  std::vector<TrainingRow> unserved;
  for (const auto& r : calibration_rows)
    if (!r.awcc_served) unserved.push_back(r);
  const auto& calibrating_rows = unserved.size() >= 100 ? unserved : calibration_rows;
  if (calibrating_rows.size() < 100) {
    result.fscc_note = fmt::format("FSCC forest uncalibrated: {} calibration runs, fewer than 100", calibration_rows.size());
  } else {
    result.fscc_calibration =
        &calibrating_rows == &unserved
            ? fmt::format("calibrated on the {} calibration runs AWCC cannot serve", unserved.size())
            : fmt::format("calibrated on all {} calibration runs (only {} that AWCC cannot serve, fewer than 100)",
                          calibration_rows.size(), unserved.size());
    std::vector<IntervalOffsets> scores(calibrating_rows.size());
    parallel_for(calibrating_rows.size(), o.threads, [&](std::size_t i) {
      const auto& r = calibrating_rows[i];
      scores[i] = interval_scores(f.velocity.quantiles(vector_of(r.features, names), correction_levels),
                                  to_target(f.form, r.true_velocity, r.features.fscc_velocity));
    });
    IntervalOffsets q{};
    for (std::size_t k = 0; k < interval_count; ++k) {
      std::vector<double> e;
      for (const auto& sc : scores) e.push_back(sc[k]);
      q[k] = conformal_offset(std::move(e), calibration_alpha[k]);
    }
    f.calibration.velocity = {q};
    f.calibration.velocity_envelope = fscc_envelope(f, calibrating_rows);
  }
  CorrectionModel scorer;  // the FSCC forest alone, with the model's margin
  scorer.range_margin = result.model.range_margin;
  scorer.fscc = f;
  scorer.use_training_envelopes();
  result.fscc_held_out = score_fscc(scorer, held_out, false);
  result.fscc_held_out_unserved = score_fscc(scorer, held_out, true);
  result.fscc_training_rows = static_cast<std::int64_t>(training.size());
  result.model.fscc = std::move(f);
  result.model.use_training_envelopes();
}

}  // namespace

namespace {

// The forests' settings from the options, before cross-validation.
struct Hyperparameters {
  ForestOptions velocity, turbulence;
  TargetForm velocity_form = TargetForm::ratio, turbulence_form = TargetForm::difference;
};

Hyperparameters initial_hyperparameters(const TrainOptions& o) {
  Hyperparameters h;
  auto& vopt = h.velocity;
  auto& topt = h.turbulence;
  vopt.trees = topt.trees = o.trees;
  vopt.threads = topt.threads = o.threads;
  vopt.seed = o.seed;
  topt.seed = o.seed + 1;
  vopt.min_leaf = topt.min_leaf = o.min_leaf;
  vopt.features_per_split = topt.features_per_split = o.features_per_split;
  h.velocity_form = o.velocity_form;
  h.turbulence_form = o.turbulence_form;
  return h;
}

// k-fold cross-validation over the target forms and the grids of min leaf
// and features per split: each target takes the least pinball loss.
void cross_validate(const std::vector<TrainingRow>& training, const TrainOptions& o,
                    const std::vector<std::string>& names, double cv_share,
                    const std::function<void(double)>& progress, Hyperparameters& h, TrainResult& result) {
  const std::size_t grid = o.min_leaf_grid.size() * o.features_per_split_grid.size() * 2;
  const auto k = static_cast<std::size_t>(o.folds);
  // Folds by run: a run's rows (its weighted and unweighted twins, side by
  // side) fall in one fold, so that no fold is scored on a run it fit.
  std::vector<std::size_t> run_ordinal(training.size());
  for (std::size_t i = 0, ordinal = 0; i < training.size(); ++i) {
    if (i > 0 && (training[i].run != training[i - 1].run || training[i].study != training[i - 1].study)) ++ordinal;
    run_ordinal[i] = ordinal;
  }
  std::size_t done = 0;
  for (int target = 0; target < 2; ++target) {
    const bool velocity = target == 0;
    const std::array<TargetForm, 2> forms{TargetForm::value, velocity ? TargetForm::ratio : TargetForm::difference};
    CvEntry best;
    best.pinball = std::numeric_limits<double>::infinity();
    for (auto form : forms) {
      for (int leaf : o.min_leaf_grid) {
        for (int mtry : o.features_per_split_grid) {
          double loss = 0.0;
          for (std::size_t fold = 0; fold < k; ++fold) {
            std::vector<TrainingRow> fit, test;
            for (std::size_t i = 0; i < training.size(); ++i)
              (run_ordinal[i] % k == fold ? test : fit).push_back(training[i]);
            ForestOptions fo;
            fo.trees = o.cv_trees;
            fo.min_leaf = leaf;
            fo.features_per_split = mtry;
            fo.seed = o.seed + 17 * fold + static_cast<std::uint64_t>(target);
            fo.threads = o.threads;
            const auto forest = QuantileForest::train(data_of(fit, velocity, form, names), fo);
            std::vector<double> losses(test.size());
            parallel_for(test.size(), o.threads, [&](std::size_t i) {
              losses[i] = target_pinball(predict(forest, form, test[i], velocity, names), test[i], velocity);
            });
            for (double l : losses) loss += l;
          }
          loss /= static_cast<double>(training.size());
          result.cv.push_back({velocity ? "velocity" : "turbulence_intensity", form, leaf, mtry, loss});
          if (loss < best.pinball) best = result.cv.back();
          if (progress) progress(cv_share * static_cast<double>(++done) / static_cast<double>(grid));
        }
      }
    }
    auto& opt = velocity ? h.velocity : h.turbulence;
    opt.min_leaf = best.min_leaf;
    opt.features_per_split = best.features_per_split;
    (velocity ? h.velocity_form : h.turbulence_form) = best.form;
  }
}

// Learning curve: the same hyperparameters on nested subsets of the training rows.
void learning_curve(const Split& split, const TrainOptions& o, const std::vector<std::string>& names,
                    const Hyperparameters& h, TrainResult& result) {
  const auto& training = split.training;
  const auto& calibration_rows = split.calibration;
  auto gain = [](const std::vector<double>& before, const std::vector<double>& after, double& mean, double& se) {
    const std::size_t n = std::min(before.size(), after.size());
    if (n < 2) return;
    double m = 0.0, q = 0.0;
    for (std::size_t i = 0; i < n; ++i) m += before[i] - after[i];
    m /= static_cast<double>(n);
    for (std::size_t i = 0; i < n; ++i) q += (before[i] - after[i] - m) * (before[i] - after[i] - m);
    mean = m;
    se = std::sqrt(q / static_cast<double>(n - 1) / static_cast<double>(n));
  };
  for (const auto& [num, den] : std::vector<std::pair<std::size_t, std::size_t>>{{1, 16}, {1, 8}, {1, 4}, {1, 2}, {3, 4}, {1, 1}}) {
    const std::size_t n = training.size() * num / den;
    if (n < 10) continue;
    const std::vector<TrainingRow> subset(training.begin(), training.begin() + static_cast<std::ptrdiff_t>(n));
    auto m = num == den ? result.model
                        : fit_model(subset, h.velocity_form, h.turbulence_form, h.velocity, h.turbulence, o.min_windows,
                                    names);
    if (num != den && !calibration_rows.empty()) {
      m.calibration = calibrate(m, calibration_rows, o.calibration_bands, o.threads, o.calibration_tu_bands);
    }
    // Every point scores the same held-out rows: those inside the full
    // model's ranges (a small subset's own ranges would drop the hard rows).
    m.ranges = result.model.ranges;
    LearningPoint point{static_cast<std::int64_t>(n), score(m, split.held_out, nullptr, o.threads)};
    if (!result.learning_curve.empty()) {
      const auto& before = result.learning_curve.back().scores;
      gain(before.velocity_losses, point.scores.velocity_losses, point.velocity_gain, point.velocity_gain_se);
      gain(before.tu_losses, point.scores.tu_losses, point.tu_gain, point.tu_gain_se);
    }
    result.learning_curve.push_back(std::move(point));
  }
}

// The model's provenance: the data, the split, the forests and their held-out scores.
std::string provenance_of(const TrainingSet& set, const TrainOptions& o, const std::vector<std::string>& names,
                          const Split& split, const Hyperparameters& hp, const TrainResult& result) {
  const auto& h = result.held_out;
  const auto& vopt = hp.velocity;
  const auto& topt = hp.turbulence;
  std::string sources;
  for (const auto& s : set.sources) sources += (sources.empty() ? "" : ", ") + s;
  std::string provenance = fmt::format(
      "pdp train {}: {} (generator version {}); {} features ({}); processed with {}{}; {} runs read, {} used ({} failed, {} without an AWCC velocity, {} with fewer than {} accepted "
      "windows, {} without a feature of the set); trained on {}, {} set aside to calibrate the intervals, {} held out (seed {}). Velocity: target {}, {} trees, min leaf {}, {} features per "
      "split. Tu: target {}, {} trees, min leaf {}, {} features per split. Held out: velocity RMSE {:.2f} % raw, "
      "{:.2f} % corrected, 80/95 % coverage {:.1f}/{:.1f} %; Tu RMSE {:.4f} raw, {:.4f} corrected, 80/95 % coverage "
      "{:.1f}/{:.1f} %.",
      awcc::version, sources, fmt::join(set.generator_versions, " and "), o.feature_set, fmt::join(names, ", "),
      describe(set.processing),
      set.processing_assumed ? " (assumed: the sweep CSVs do not record it)" : "", set.total, set.rows.size() - static_cast<std::size_t>(result.excluded_features), set.excluded_error,
      set.excluded_undefined, set.excluded_windows, o.min_windows, result.excluded_features, split.training.size(), split.calibration.size(), split.held_out.size(), o.seed,
      to_string(hp.velocity_form), vopt.trees, vopt.min_leaf, vopt.features_per_split, to_string(hp.turbulence_form),
      topt.trees, topt.min_leaf, topt.features_per_split, 100 * h.velocity_rmse_raw, 100 * h.velocity_rmse_corrected,
      100 * h.velocity_coverage80, 100 * h.velocity_coverage95, h.tu_rmse_raw, h.tu_rmse_corrected,
      100 * h.tu_coverage80, 100 * h.tu_coverage95);
  if (result.model.fscc) {
    const auto& f = result.fscc_held_out;
    const auto& u = result.fscc_held_out_unserved;
    provenance += fmt::format(
        " FSCC forest (velocity of rows without a usable AWCC result; features {}): trained on {} runs{}; held out, the "
        "runs AWCC "
        "cannot serve ({} rows): velocity RMSE {:.2f} % raw FSCC, {:.2f} % corrected, 80/95 % coverage {:.1f}/{:.1f} %; "
        "all runs with an FSCC velocity ({} rows): RMSE {:.2f} % raw, {:.2f} % corrected, coverage {:.1f}/{:.1f} %.",
        fmt::join(names_of(result.model.fscc->ranges), ", "), result.fscc_training_rows,
        result.fscc_calibration.empty() ? "" : ", " + result.fscc_calibration, u.rows,
        100 * u.rmse_raw, 100 * u.rmse_corrected, 100 * u.coverage80, 100 * u.coverage95, f.rows, 100 * f.rmse_raw,
        100 * f.rmse_corrected, 100 * f.coverage80, 100 * f.coverage95);
  }
  if (!result.fscc_note.empty()) provenance += " " + result.fscc_note + ".";
  provenance += fmt::format(" Trust rules (model.hpp): {} of the {} scored held-out runs untrusted by the AWCC forests "
                            "({} outside the envelope, {} multimodal, {} at a lag of one sample, {} at a chance "
                            "yield)",
                            h.untrusted, h.rows, h.outside_envelope, h.multimodal, h.one_sample_lag, h.chance_yield);
  if (result.model.fscc) {
    const auto& u = result.fscc_held_out_unserved;
    provenance += fmt::format(", {} of {} by the FSCC forest ({} outside the envelope, {} multimodal, {} at a lag of "
                              "one sample)",
                              u.untrusted, u.rows, u.outside_envelope, u.multimodal, u.one_sample_lag);
  }
  return provenance + ".";
}

}  // namespace

namespace {

// The reduced model (CorrectionModel::reduced): the measured features of the
// same training runs, the same hyperparameters, its intervals calibrated
// pooled over the window bands (a peer's row states no windows, so every
// record length and rate it stands for is one group), scored on the
// held-out runs with their record features removed. Its answer is the
// average over the training runs' record lengths and rates, sweeps at one
// fs and duration included: without the two at 60 s and 500 kHz (a fifth of
// the campaign's runs) it scored worse on the foreign sets as peers' rows
// (u median error 1.5 to 1.95 %, Tu bias +0.008 to +0.022 on the control
// set; docs/history/correction-foreign-conventions.md, "The model of the
// complete campaign, shipped"), whose records are also at 500 kHz.
void train_reduced(const Split& split, const TrainOptions& o, const Hyperparameters& h, const Processing& processing,
                   TrainResult& result) {
  const auto names = feature_set_names(result.model.takes_weighting() ? "measured+weighting" : "measured");
  const int most = static_cast<int>(names.size());
  ForestOptions velocity = h.velocity, turbulence = h.turbulence;
  velocity.features_per_split = std::min(velocity.features_per_split, most);
  turbulence.features_per_split = std::min(turbulence.features_per_split, most);
  auto reduced = fit_model(split.training, h.velocity_form, h.turbulence_form, velocity, turbulence, o.min_windows, names);
  if (!split.calibration.empty()) {
    reduced.calibration = calibrate(reduced, split.calibration, {}, o.threads, o.calibration_tu_bands);
  }
  reduced.processing = processing;
  reduced.provenance = fmt::format("the reduced model (features {}) of the model below, trained on its {} training "
                                   "runs and calibrated on its {} calibration runs pooled over the window bands",
                                   fmt::join(names, ", "), split.training.size(), split.calibration.size());
  const auto stripped = as_peer_rows(split.held_out);
  result.model.reduced = std::make_shared<const CorrectionModel>(std::move(reduced));
  result.reduced_held_out = score(result.model, stripped, &result.reduced_predictions, o.threads);
}

}  // namespace

TrainResult train_model(const TrainingSet& set, const TrainOptions& o, const std::function<void(double)>& progress) {
  o.validate().throw_if_failed();
  const auto names = feature_set_names(o.feature_set);
  // Runs without a feature of the set are left out and counted (the FSCC
  // forest still takes them from set.fscc_rows where it can).
  std::vector<TrainingRow> rows;
  rows.reserve(set.rows.size());
  std::copy_if(set.rows.begin(), set.rows.end(), std::back_inserter(rows), [&](const TrainingRow& r) {
    return std::all_of(names.begin(), names.end(), [&](const std::string& n) { return r.features.value(n).has_value(); });
  });
  if (rows.empty() && !set.rows.empty()) {
    for (const auto& n : names) {
      if (!set.rows.front().features.value(n)) {
        throw awcc::OptionError(fmt::format("no training run has {} (the sweep CSVs lack the column, or no run has a "
                                            "value): train another feature set, or give sweeps that record it",
                                            n),
                                "feature-set");
      }
    }
  }
  TrainResult result;
  result.excluded_features = static_cast<std::int64_t>(set.rows.size() - rows.size());
  Split split = split_runs(rows, o);
  split.training = with_saturated_durations(std::move(split.training));
  const std::size_t runs = rows.size();
  const bool twins = names.back() == Features::weighting_name;
  if (twins) {
    // Each run measured both ways, its twins side by side in its part.
    for (auto* part : {&split.held_out, &split.calibration, &split.training}) *part = with_unweighted_twins(*part);
  }
  if (split.held_out.empty() || split.held_out.size() >= runs) {
    throw awcc::OptionError(fmt::format("{} usable runs cannot be split {:.0f}/{:.0f}; run a larger sweep", runs,
                                        100 * (1 - o.held_out), 100 * o.held_out),
                            "held-out");
  }
  // The calibration runs come next in the same order; the forests never see them.
  if (o.calibration > 0.0 && split.calibration.size() < 100) {
    throw awcc::OptionError(fmt::format("{} calibration runs are too few to calibrate the 95 % interval of each "
                                        "band; run a larger sweep or set calibration to 0",
                                        split.calibration.size()),
                            "calibration");
  }

  result.training_rows = static_cast<std::int64_t>(split.training.size());
  Hyperparameters h = initial_hyperparameters(o);
  const auto cv_start = std::chrono::steady_clock::now();
  const double cv_share = o.folds >= 2 ? 0.7 : 0.0;
  if (o.folds >= 2) cross_validate(split.training, o, names, cv_share, progress, h, result);
  result.seconds_cv = seconds_since(cv_start);
  result.velocity_min_leaf = h.velocity.min_leaf;
  result.velocity_features_per_split = h.velocity.features_per_split;
  result.turbulence_min_leaf = h.turbulence.min_leaf;
  result.turbulence_features_per_split = h.turbulence.features_per_split;

  const auto train_start = std::chrono::steady_clock::now();
  result.model = fit_model(split.training, h.velocity_form, h.turbulence_form, h.velocity, h.turbulence, o.min_windows,
                           names);
  if (!split.calibration.empty()) {
    result.model.calibration =
        calibrate(result.model, split.calibration, o.calibration_bands, o.threads, o.calibration_tu_bands);
  }
  result.calibration_rows = static_cast<std::int64_t>(split.calibration.size());
  if (o.feature_set != "measured") train_fscc(set, o, h.velocity, result);
  if (o.feature_set != "measured" && o.reduced) train_reduced(split, o, h, set.processing, result);
  result.seconds_train = seconds_since(train_start);
  result.held_out = score(result.model, split.held_out, &result.predictions, o.threads);
  if (progress) progress(cv_share + 0.1);
  learning_curve(split, o, names, h, result);
  if (progress) progress(1.0);
  result.model.processing = set.processing;
  result.model.provenance = provenance_of(set, o, names, split, h, result);
  return result;
}

void require_model_processing(const CorrectionModel& model, const TrainingSet& set) {
  if (const auto why = model.mismatch(set.processing); !why.empty()) {
    throw awcc::InputError(fmt::format("the runs were processed differently from the model's training data ({}); "
                                       "run the sweeps with the model's method options",
                                       why));
  }
}

TrustResult measure_trust(CorrectionModel model, const TrainingSet& set, const TrainOptions& o) {
  o.validate().throw_if_failed();
  require_model_processing(model, set);
  TrainOptions split_options = o;
  split_options.calibration = 0.0;  // held out, and the rest measures the envelopes
  std::vector<std::string> names;
  for (const auto& r : model.ranges) names.push_back(r.name);
  // The rows each forest takes (inside its ranges, enough windows).
  std::vector<TrainingRow> rows, fscc_rows;
  for (const auto& r : set.rows)
    if (model.correct(r.features).velocity) rows.push_back(r);
  if (model.fscc) {
    for (const auto& r : set.fscc_rows)
      if (!r.awcc_served && model.correct_fscc(r.features).velocity) fscc_rows.push_back(r);
  }
  const Split split = split_runs(rows, split_options);
  const Split fscc_split = split_runs(fscc_rows, split_options);
  const auto& measuring = split.training;
  auto& c = model.calibration;
  std::vector<int> band(measuring.size()), tu_band(measuring.size());
  std::vector<std::array<double, 2>> shifts(measuring.size());
  parallel_for(measuring.size(), o.threads, [&](std::size_t i) {
    const auto& r = measuring[i];
    const auto& f = r.features;
    const auto tu = model.turbulence_intensity.quantiles(vector_of(f, names), std::array<double, 1>{0.5});
    band[i] = c.band(f.windows_accepted);
    tu_band[i] = c.tu_band(from_target(model.turbulence_form, tu[0], f.turbulence_intensity));
    shifts[i] = {to_target(model.velocity_form, r.true_velocity, f.velocity) -
                     to_target(model.velocity_form, f.velocity, f.velocity),
                 to_target(model.turbulence_form, r.true_turbulence_intensity, f.turbulence_intensity) -
                     to_target(model.turbulence_form, f.turbulence_intensity, f.turbulence_intensity)};
  });
  set_envelopes(c, model, band, tu_band, shifts);
  TrustResult result;
  result.envelope_rows = static_cast<std::int64_t>(measuring.size());
  if (model.fscc) {
    if (auto e = fscc_envelope(*model.fscc, fscc_split.training); !e.empty()) {
      model.fscc->calibration.velocity_envelope = std::move(e);
      model.fscc->calibration.envelope_from_training = false;
    }
    result.fscc_envelope_rows = static_cast<std::int64_t>(fscc_split.training.size());
  }
  result.held_out = score(model, split.held_out, nullptr, o.threads);
  if (model.fscc) result.fscc_held_out_unserved = score_fscc(model, fscc_split.held_out, true);
  std::string sources;
  for (const auto& src : set.sources) sources += (sources.empty() ? "" : ", ") + src;
  const auto& h = result.held_out;
  const auto& u = result.fscc_held_out_unserved;
  result.summary = fmt::format(
      "Trust envelopes (rule (a), model.hpp) measured by pdp train {} on runs the model was not trained on ({}): the "
      "AWCC forests' on {} runs{}, {}; the FSCC forest's on {} runs it takes that AWCC cannot serve{}. Held out of "
      "those runs: {} of {} untrusted by the AWCC forests ({} outside the envelope, {} multimodal, {} at a lag of one "
      "sample, {} at a chance yield), {} of {} by the FSCC forest ({} outside the envelope, {} multimodal, {} at a "
      "lag of one sample).",
      awcc::version, sources, measuring.size(),
      c.envelope_from_training ? " (too few: the training targets' kept)" : "",
      c.envelope_from_training ? "pooled" : "per window and Tu band where a band has 399 runs",
      fscc_split.training.size(),
      model.fscc && model.fscc->calibration.envelope_from_training ? " (too few: the training targets' kept)" : "",
      h.untrusted, h.rows, h.outside_envelope, h.multimodal, h.one_sample_lag, h.chance_yield, u.untrusted, u.rows,
      u.outside_envelope, u.multimodal, u.one_sample_lag);
  model.provenance += " " + result.summary;
  result.model = std::move(model);
  return result;
}

}  // namespace correction
