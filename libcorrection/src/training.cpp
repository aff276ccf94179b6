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

namespace correction {

namespace {

using awcc::cell_number;
using awcc::mix64;
using awcc::parallel_for;
using awcc::split_cells;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<double> levels() { return {correction_levels.begin(), correction_levels.end()}; }

std::vector<std::string> names_of(const std::vector<FeatureRange>& ranges) {
  std::vector<std::string> names;
  for (const auto& r : ranges) names.push_back(r.name);
  return names;
}

// A training row's feature vector in the order of `names` (every value is
// there: load_training_set reads them all).
std::vector<double> vector_of(const Features& f, const std::vector<std::string>& names) {
  std::vector<double> x;
  x.reserve(names.size());
  for (const auto& n : names) {
    const auto v = f.value(n);
    if (!v) {
      throw awcc::OptionError(fmt::format("a training run has no {} (the sweep CSV lacks the column, or the run has "
                                          "no value): train another feature set, or give sweeps that record it",
                                          n),
                              "feature-set");
    }
    x.push_back(*v);
  }
  return x;
}

TrainingData data_of(const std::vector<TrainingRow>& rows, bool velocity, TargetForm form,
                     const std::vector<std::string>& names) {
  TrainingData d;
  d.features = static_cast<int>(names.size());
  d.x.reserve(rows.size() * names.size());
  d.y.reserve(rows.size());
  for (const auto& r : rows) {
    const auto x = vector_of(r.features, names);
    d.x.insert(d.x.end(), x.begin(), x.end());
    d.y.push_back(velocity ? to_target(form, r.true_velocity, r.features.velocity)
                           : to_target(form, r.true_turbulence_intensity, r.features.turbulence_intensity));
  }
  return d;
}

// Pinball loss of one target's quantiles in the units of the scores
// (velocity relative to the truth, Tu absolute).
double target_pinball(const std::vector<double>& q, const TrainingRow& r, bool velocity) {
  const auto lv = levels();
  if (velocity) {
    std::vector<double> rel(q.size());
    for (std::size_t k = 0; k < q.size(); ++k) rel[k] = q[k] / r.true_velocity;
    return pinball_loss(rel, lv, 1.0);
  }
  return pinball_loss(q, lv, r.true_turbulence_intensity);
}

std::vector<double> predict(const QuantileForest& f, TargetForm form, const TrainingRow& r, bool velocity,
                            const std::vector<std::string>& names) {
  const auto x = vector_of(r.features, names);
  auto q = f.quantiles(x, levels());
  const double measured = velocity ? r.features.velocity : r.features.turbulence_intensity;
  for (auto& v : q) {
    v = from_target(form, v, measured);
    if (!velocity) v = std::max(0.0, v);
  }
  return q;
}

}  // namespace

namespace {

std::vector<int> whole_list(std::string_view text, long long lo, long long hi) {
  std::vector<int> out;
  for (const auto& item : split_cells(text)) out.push_back(static_cast<int>(awcc::parse_whole(item, lo, hi)));
  return out;
}

std::string list_text(const std::vector<int>& values) {
  std::string out;
  for (int v : values) out += (out.empty() ? "" : ",") + std::to_string(v);
  return out;
}

using T = TrainOptions;
const awcc::OptionField<T> kTraining[] = {
    {"trees", "-", "trees per forest: more give smoother quantiles at proportional cost",
     [](T& o, std::string_view t) { o.trees = static_cast<int>(awcc::parse_whole(t, 1, 100000)); },
     [](const T& o) { return std::to_string(o.trees); }},
    {"min-windows", "-", "runs with fewer accepted AWCC windows are left out (and counted); rows below it are not corrected",
     [](T& o, std::string_view t) { o.min_windows = awcc::parse_whole(t, 1, std::int64_t{1} << 40); },
     [](const T& o) { return std::to_string(o.min_windows); }},
    {"held-out", "-", "fraction of runs held out for the report (never trained on)",
     [](T& o, std::string_view t) { o.held_out = awcc::parse_quantity(t, awcc::Dimension::dimensionless); },
     [](const T& o) { return fmt::format("{:g}", o.held_out); }},
    {"folds", "-", "cross-validation folds over the hyperparameter grids; 0 = none (the grids' first values)",
     [](T& o, std::string_view t) { o.folds = static_cast<int>(awcc::parse_whole(t, 0, 100)); },
     [](const T& o) { return std::to_string(o.folds); }},
    {"cv-trees", "-", "trees per forest during cross-validation (fewer: a faster search)",
     [](T& o, std::string_view t) { o.cv_trees = static_cast<int>(awcc::parse_whole(t, 1, 100000)); },
     [](const T& o) { return std::to_string(o.cv_trees); }},
    {"min-leaf", "-", "least training draws per leaf: the values tried",
     [](T& o, std::string_view t) {
       o.min_leaf_grid = whole_list(t, 1, 1000000);
       o.min_leaf = o.min_leaf_grid.front();
     },
     [](const T& o) { return list_text(o.min_leaf_grid); }},
    {"calibration", "-",
     "fraction of the training runs set aside to calibrate the 50/80/95 % intervals (conformalised); 0 = none",
     [](T& o, std::string_view t) { o.calibration = awcc::parse_quantity(t, awcc::Dimension::dimensionless); },
     [](const T& o) { return fmt::format("{:g}", o.calibration); }},
    {"calibration-bands", "-", "accepted-window counts where the calibration bands meet (each band is calibrated on its own)",
     [](T& o, std::string_view t) {
       o.calibration_bands.clear();
       for (int v : whole_list(t, 1, 1 << 30)) o.calibration_bands.push_back(v);
     },
     [](const T& o) {
       std::vector<int> v(o.calibration_bands.begin(), o.calibration_bands.end());
       return list_text(v);
     }},
    {"calibration-tu-bands", "-",
     "values of the model's Tu where the calibration's Tu bands meet (each band of windows and Tu is calibrated on its "
     "own); none = one Tu band",
     [](T& o, std::string_view t) {
       o.calibration_tu_bands.clear();
       if (t == "none") return;
       for (const auto& cell : awcc::split_cells(t)) {
         o.calibration_tu_bands.push_back(awcc::parse_quantity(cell, awcc::Dimension::dimensionless));
       }
     },
     [](const T& o) {
       if (o.calibration_tu_bands.empty()) return std::string("none");
       std::string s;
       for (double v : o.calibration_tu_bands) s += (s.empty() ? "" : ",") + fmt::format("{:g}", v);
       return s;
     }},
    {"feature-set", "-",
     "features of the model: measured (u, Tu, c, d32, dx, dy, Np), extended (also fs, duration and accepted "
     "windows) or extended-yield (fs, duration and the data yield); an extended set may end in +lag (AWCC's lag "
     "in samples, dx fs / u), then +scale (AWCC's T_u / T_W, capped at 20), any in +weighting (how AWCC's moments "
     "were taken)",
     [](T& o, std::string_view t) {
       feature_set_names(t);  // refuses an unknown set
       o.feature_set = std::string(t);
     },
     [](const T& o) { return o.feature_set; }},
    {"fscc-feature-set", "-",
     "features of the FSCC forest: fscc (u_FSCC, R12max, c, d32 from u_FSCC, dx, dy, fs, duration) or fscc-2 (c / F "
     "and FSCC's lag dx / u_FSCC in place of that d32)",
     [](T& o, std::string_view t) {
       if (t != "fscc" && t != "fscc-2") throw std::invalid_argument(fmt::format("'{}': write fscc or fscc-2", t));
       o.fscc_feature_set = std::string(t);
     },
     [](const T& o) { return o.fscc_feature_set; }},
    {"reduced", "-",
     "with an extended feature set, also train the reduced model (u, Tu, c, d32, dx, dy, Np) that corrects rows "
     "without fs, duration or windows (peers' files): on | off",
     [](T& o, std::string_view t) {
       if (t != "on" && t != "off") throw std::invalid_argument(fmt::format("'{}': write on or off", t));
       o.reduced = t == "on";
     },
     [](const T& o) { return std::string(o.reduced ? "on" : "off"); }},
    {"features-per-split", "-", "features tried per split (1 to the feature count): the values tried",
     [](T& o, std::string_view t) {
       o.features_per_split_grid =
           whole_list(t, 1, static_cast<std::int64_t>(Features::names.size() + Features::record_names.size() + 1));
       o.features_per_split = o.features_per_split_grid.front();
     },
     [](const T& o) { return list_text(o.features_per_split_grid); }},
    {"seed", "-", "seed of the split, the folds and the forests",
     [](T& o, std::string_view t) { o.seed = static_cast<std::uint64_t>(awcc::parse_whole(t, 0, std::int64_t{1} << 53)); },
     [](const T& o) { return std::to_string(o.seed); }},
    {"threads", "-", "threads (0 = all cores); the model is the same for any count",
     [](T& o, std::string_view t) { o.threads = static_cast<int>(awcc::parse_whole(t, 0, 4096)); },
     [](const T& o) { return std::to_string(o.threads); }},
};

}  // namespace

std::span<const awcc::OptionField<TrainOptions>> training_option_fields() { return kTraining; }

awcc::Validation TrainOptions::validate() const {
  using awcc::Validation;
  if (trees < 1) return Validation::invalid("trees", fmt::format("trees {}: give at least 1", trees));
  if (min_windows < 1)
    return Validation::invalid("min-windows", fmt::format("minimum windows {}: give at least 1", min_windows));
  if (!(held_out > 0.0 && held_out < 1.0))
    return Validation::invalid("held-out", fmt::format("held-out fraction {}: give a fraction in (0, 1)", held_out));
  if (folds == 1 || folds < 0)
    return Validation::invalid("folds", fmt::format("folds {}: give 0 (no cross-validation) or at least 2", folds));
  if (cv_trees < 1)
    return Validation::invalid("cv-trees", fmt::format("cross-validation trees {}: give at least 1", cv_trees));
  if (min_leaf < 1) return Validation::invalid("min-leaf", fmt::format("min leaf {}: give at least 1", min_leaf));
  if (!(calibration >= 0.0 && calibration < 1.0)) {
    return Validation::invalid("calibration",
                               fmt::format("calibration fraction {}: give a fraction in [0, 1)", calibration));
  }
  for (std::size_t i = 1; i < calibration_bands.size(); ++i) {
    if (calibration_bands[i] <= calibration_bands[i - 1])
      return Validation::invalid("calibration-bands", "calibration bands: give increasing window counts");
  }
  for (std::size_t i = 0; i < calibration_tu_bands.size(); ++i) {
    if (!std::isfinite(calibration_tu_bands[i]) || (i > 0 && calibration_tu_bands[i] <= calibration_tu_bands[i - 1])) {
      return Validation::invalid("calibration-tu-bands", "calibration Tu bands: give increasing values of Tu");
    }
  }
  std::size_t features = 0;
  try {
    features = feature_set_names(feature_set).size();
  } catch (const std::invalid_argument& e) {
    return Validation::invalid("feature-set", e.what());
  }
  for (int m : features_per_split_grid) {
    if (m < 1 || static_cast<std::size_t>(m) > features) {
      return Validation::invalid("features-per-split", fmt::format("features per split {}: give 1 to {} (the {} feature set)",
                                                                   m, features, feature_set));
    }
  }
  if (features_per_split < 1 || static_cast<std::size_t>(features_per_split) > features) {
    return Validation::invalid("features-per-split",
                               fmt::format("features per split {}: give 1 to {}", features_per_split, features));
  }
  return {};
}

std::string_view to_string(TruthKind truth) { return truth == TruthKind::realised ? "realised" : "imposed"; }

std::optional<TruthKind> truth_kind_of(std::string_view text) {
  if (text == "realised") return TruthKind::realised;
  if (text == "imposed") return TruthKind::imposed;
  return std::nullopt;
}

TrainingSet load_training_set(const std::vector<std::filesystem::path>& csvs, std::int64_t min_windows,
                              TruthKind truth) {
  TrainingSet set;
  std::set<std::pair<std::string, std::int64_t>> seen;
  bool processing_seen = false;
  for (const auto& path : csvs) {
    std::ifstream in(path);
    if (!in) throw awcc::InputError(fmt::format("{}: cannot open the sweep CSV; check the path", path.string()));
    std::string line;
    if (!std::getline(in, line)) throw awcc::InputError(fmt::format("{}: empty file; give a CSV written by pdp sweep", path.string()));
    const auto header = awcc::csv_header(line);
    const auto& col = header.index;
    using C = SweepColumn;
    using Scene = SweepSceneColumns;
    const std::string_view needed[] = {sweep_key_columns[0].name, sweep_key_columns[1].name, Scene::dx, Scene::dy,
                                       column_name(C::np), column_name(C::truth_velocity),
                                       column_name(C::truth_turbulence_intensity), column_name(C::awcc_velocity),
                                       column_name(C::awcc_turbulence_intensity), column_name(C::awcc_void_fraction),
                                       column_name(C::awcc_count_rate), column_name(C::awcc_windows_accepted),
                                       column_name(C::reason),
                                       truth == TruthKind::imposed ? Scene::velocity : column_name(C::truth_velocity),
                                       truth == TruthKind::imposed ? Scene::tu : column_name(C::truth_velocity)};
    for (const auto name : needed) {
      if (!col.count(name)) {
        throw awcc::InputError(fmt::format("{}: no column '{}'; give a CSV written by pdp sweep", path.string(), name));
      }
    }
    // The processing of the runs: every row must agree (the model learns one).
    // Sweeps written before these columns existed have none of them.
    const C processing_columns[] = {C::awcc_filter_a, C::awcc_roc, C::awcc_weighting, C::awcc_signal, C::awcc_subsample};
    const bool has_processing = std::all_of(std::begin(processing_columns), std::end(processing_columns),
                                            [&](C c) { return col.count(column_name(c)) > 0; });
    if (!has_processing) set.processing_assumed = true;
    // The geometry processed; older CSVs have only the scene's dx and dy
    // (the same unless the scene gave explicit tips).
    const std::string_view dx_column = col.count(column_name(C::probe_dx)) ? column_name(C::probe_dx) : Scene::dx;
    const std::string_view dy_column = col.count(column_name(C::probe_dy)) ? column_name(C::probe_dy) : Scene::dy;
    const std::string_view study_column = sweep_key_columns[0].name, run_column = sweep_key_columns[1].name;
    const bool has_version = col.count(column_name(C::generator_version)) > 0;
    std::set<std::string> studies;
    std::int64_t number = 1;
    while (std::getline(in, line)) {
      ++number;
      if (line.empty()) continue;
      const auto cells = split_cells(line);
      if (cells.size() != header.names.size()) {
        throw awcc::InputError(fmt::format("{}:{}: {} cells where the header has {}; a sweep CSV cut short? pdp sweep "
                                           "resumes and repairs it",
                                           path.string(), number, cells.size(), header.names.size()));
      }
      auto cell = [&](std::string_view name) -> const std::string& { return cells[col.find(name)->second]; };
      auto number_of = [&](std::string_view name) {
        const auto v = cell_number(cell(name));
        if (!v) {
          throw awcc::InputError(fmt::format("{}:{}: column {} = '{}' is not a number; give the CSV pdp sweep wrote",
                                             path.string(), number, name, cell(name)));
        }
        return *v;
      };
      ++set.total;
      studies.insert(cell(study_column));
      // Rows written before the column existed are generator version 1.
      set.generator_versions.insert(has_version ? static_cast<int>(number_of(column_name(C::generator_version))) : 1);
      const auto run = static_cast<std::int64_t>(number_of(run_column));
      if (!seen.insert({cell(study_column), run}).second) {
        throw awcc::InputError(fmt::format("{}:{}: run {} of study {} was already read; give each sweep CSV once",
                                           path.string(), number, run, cell(study_column)));
      }
      // A failed run has no result at all (no truth); a run whose AWCC gave
      // no value has its truth but no AWCC velocity.
      if (cell(column_name(C::truth_velocity)).empty()) {
        ++set.excluded_error;
        continue;
      }
      if (has_processing) {
        // An enum cell that names no value is refused: a default would train
        // a model on a processing the runs did not have.
        auto named = [&](C column, auto parse, std::string_view values) {
          const auto v = parse(cell(column_name(column)));
          if (!v) {
            throw awcc::InputError(fmt::format("{}:{}: column {} = '{}' is not one of {}; give the CSV pdp sweep wrote",
                                               path.string(), number, column_name(column), cell(column_name(column)),
                                               values));
          }
          return *v;
        };
        Processing p;
        p.filter_a = number_of(column_name(C::awcc_filter_a));
        p.roc = named(C::awcc_roc, roc_of, "on, off");
        p.weighting = named(C::awcc_weighting, weighting_of, "duration, none");
        p.signal = named(C::awcc_signal, signal_of, "binary, raw");
        p.subsample = named(C::awcc_subsample, subsample_of, "none, parabolic, gaussian, triangle, centroid");
        if (!processing_seen) set.processing = p;
        processing_seen = true;
        if (const auto why = processing_mismatch(set.processing, p); !why.empty()) {
          throw awcc::InputError(fmt::format("{}:{}: this run was processed differently from the first ({}); a model "
                                             "learns one processing: train on sweeps run with the same method options",
                                             path.string(), number, why));
        }
      }
      TrainingRow r;
      r.run = run;
      try {
        std::size_t used = 0;
        r.study = std::stoull(cell(study_column), &used);
        if (used != cell(study_column).size()) throw std::invalid_argument("trailing text");
      } catch (const std::exception&) {
        throw awcc::InputError(fmt::format("{}:{}: study = '{}' is not a sweep study id; give the CSV pdp sweep wrote",
                                           path.string(), number, cell(study_column)));
      }
      Measurement m;
      if (!cell(column_name(C::awcc_velocity)).empty()) m.velocity = number_of(column_name(C::awcc_velocity));
      if (!cell(column_name(C::awcc_turbulence_intensity)).empty())
        m.turbulence_intensity = number_of(column_name(C::awcc_turbulence_intensity));
      auto optional_number = [&](std::string_view name) -> std::optional<double> {
        return col.count(name) && !cell(name).empty() ? std::optional(number_of(name)) : std::nullopt;
      };
      // The phase statistics and the record are there for every run that did not fail.
      m.void_fraction = optional_number(column_name(C::awcc_void_fraction)).value_or(0.0);
      m.bubble_count_rate = optional_number(column_name(C::awcc_count_rate)).value_or(0.0);
      m.dx = number_of(dx_column);
      m.dy = number_of(dy_column);
      m.np = static_cast<int>(number_of(column_name(C::np)));
      m.windows_accepted =
          static_cast<std::int64_t>(optional_number(column_name(C::awcc_windows_accepted)).value_or(-1.0));
      m.windows_total = static_cast<std::int64_t>(optional_number(column_name(C::awcc_windows_total)).value_or(-1.0));
      m.fs = optional_number(Scene::fs).value_or(0.0);
      m.duration = optional_number(Scene::duration).value_or(0.0);
      m.fscc_velocity = optional_number(column_name(C::fscc_velocity));
      m.r12_max = optional_number(column_name(C::fscc_r12_max));
      m.time_scale_ratio = optional_number(column_name(C::awcc_time_scale_ratio));
      // Every row of a set shares one processing (checked above); runs
      // without the columns were processed with the defaults.
      m.weighting = has_processing ? set.processing.weighting : awcc::Weighting::duration;
      const auto features = make_features(m);
      if (truth == TruthKind::realised) {
        r.true_velocity = number_of(column_name(C::truth_velocity));
        r.true_turbulence_intensity = number_of(column_name(C::truth_turbulence_intensity));
      } else {
        r.true_velocity = number_of(Scene::velocity);
        r.true_turbulence_intensity = number_of(Scene::tu);
      }
      if (fscc_unusable(features.features).empty() && features.features.fs > 0.0 && features.features.duration > 0.0) {
        TrainingRow f = r;
        f.features = features.features;
        f.awcc_served = features.ok() && features.features.windows_accepted >= min_windows;
        set.fscc_rows.push_back(f);
      }
      if (!features.ok()) {  // no (positive) AWCC velocity, or no bubbles: not corrected either
        ++set.excluded_undefined;
        continue;
      }
      if (features.features.windows_accepted < min_windows) {
        ++set.excluded_windows;
        continue;
      }
      r.features = features.features;
      // The same windows' unweighted moments, where the sweep wrote them.
      const auto u_unweighted = optional_number(column_name(C::awcc_velocity_unweighted));
      const auto tu_unweighted = optional_number(column_name(C::awcc_turbulence_intensity_unweighted));
      if (u_unweighted && tu_unweighted) {
        Measurement twin = m;
        twin.velocity = u_unweighted;
        twin.turbulence_intensity = tu_unweighted;
        twin.weighting = awcc::Weighting::none;
        if (const auto t = make_features(twin); t.ok()) r.unweighted = t.features;
      }
      set.rows.push_back(r);
    }
    for (const auto& s : studies) set.sources.push_back(fmt::format("{} (study {})", path.filename().string(), s));
  }
  if (set.rows.empty()) {
    throw awcc::InputError(fmt::format("no usable runs in the sweep CSVs ({} read: {} failed, {} without an AWCC "
                                       "velocity, {} with fewer than {} accepted windows): give sweeps with usable "
                                       "runs, or lower min-windows",
                                       set.total, set.excluded_error, set.excluded_undefined, set.excluded_windows,
                                       min_windows),
                           "min-windows");
  }
  return set;
}

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

// The statistics of one quantity (velocity or Tu) over the scored rows.
struct QuantityScores {
  double square_raw = 0.0, square_corrected = 0.0, sum_raw = 0.0, sum_corrected = 0.0;
  double pinball = 0.0, covered80 = 0.0, covered95 = 0.0;
  std::vector<double> abs_raw, abs_corrected, losses;

  void add(double raw_error, double corrected_error, double truth, const std::array<double, 7>& q, double loss) {
    square_raw += raw_error * raw_error;
    square_corrected += corrected_error * corrected_error;
    sum_raw += raw_error;
    sum_corrected += corrected_error;
    abs_raw.push_back(std::fabs(raw_error));
    abs_corrected.push_back(std::fabs(corrected_error));
    losses.push_back(loss);
    pinball += loss;
    covered80 += (truth >= q[1] && truth <= q[5]) ? 1.0 : 0.0;
    covered95 += (truth >= q[0] && truth <= q[6]) ? 1.0 : 0.0;
  }

  /// rmse, median |error|, mean error (raw, corrected), pinball, coverages.
  void finish(double& rmse_raw, double& rmse_corrected, double& median_raw, double& median_corrected,
              double& bias_raw, double& bias_corrected, double& mean_pinball, double& coverage80,
              double& coverage95, std::vector<double>& row_losses) {
    median_raw = awcc::median(abs_raw);
    median_corrected = awcc::median(abs_corrected);
    row_losses = std::move(losses);
    const auto n = static_cast<double>(abs_raw.size());
    if (n == 0) return;
    rmse_raw = std::sqrt(square_raw / n);
    rmse_corrected = std::sqrt(square_corrected / n);
    bias_raw = sum_raw / n;
    bias_corrected = sum_corrected / n;
    mean_pinball = pinball / n;
    coverage80 = covered80 / n;
    coverage95 = covered95 / n;
  }
};

}  // namespace

HeldOutScores score(const CorrectionModel& model, const std::vector<TrainingRow>& rows,
                    std::vector<HeldOutPrediction>* predictions, int threads) {
  std::vector<Correction> c(rows.size());
  parallel_for(rows.size(), threads, [&](std::size_t i) { c[i] = model.correct(rows[i].features); });
  HeldOutScores s;
  QuantityScores velocity, tu;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    if (predictions) predictions->push_back({r, c[i]});
    if (!c[i].velocity || !c[i].turbulence_intensity) {
      ++s.out_of_range;
      continue;
    }
    ++s.rows;
    s.untrusted += c[i].status == CorrectionStatus::untrusted;
    s.outside_envelope += c[i].outside_envelope;
    s.multimodal += c[i].multimodal;
    s.one_sample_lag += c[i].one_sample_lag;
    s.chance_yield += c[i].chance_yield;
    s.large_bubbles += c[i].large_bubbles;
    const auto& u = *c[i].velocity;
    const auto& t = *c[i].turbulence_intensity;
    const std::vector<double> uq(u.quantiles.begin(), u.quantiles.end()), tq(t.quantiles.begin(), t.quantiles.end());
    // Velocity relative to the truth, Tu absolute.
    velocity.add(r.features.velocity / r.true_velocity - 1.0, u.median() / r.true_velocity - 1.0, r.true_velocity,
                 u.quantiles, target_pinball(uq, r, true));
    tu.add(r.features.turbulence_intensity - r.true_turbulence_intensity, t.median() - r.true_turbulence_intensity,
           r.true_turbulence_intensity, t.quantiles, target_pinball(tq, r, false));
  }
  velocity.finish(s.velocity_rmse_raw, s.velocity_rmse_corrected, s.velocity_median_abs_raw,
                  s.velocity_median_abs_corrected, s.velocity_bias_raw, s.velocity_bias_corrected, s.velocity_pinball,
                  s.velocity_coverage80, s.velocity_coverage95, s.velocity_losses);
  tu.finish(s.tu_rmse_raw, s.tu_rmse_corrected, s.tu_median_abs_raw, s.tu_median_abs_corrected, s.tu_bias_raw,
            s.tu_bias_corrected, s.tu_pinball, s.tu_coverage80, s.tu_coverage95, s.tu_losses);
  return s;
}

namespace {

// The 50, 80 and 95 % intervals' miscoverage.
constexpr std::array<double, 3> calibration_alpha{0.5, 0.2, 0.05};

// Q = E_k, k = ceil((n + 1)(1 - alpha)) of the scores (model.hpp, Calibration).
// With k > n the guarantee needs Q = infinity: too few runs, refused.
double conformal_offset(std::vector<double> e, double alpha) {
  std::sort(e.begin(), e.end());
  const auto n = static_cast<double>(e.size());
  const auto rank = static_cast<std::size_t>(std::ceil((n + 1.0) * (1.0 - alpha)));
  if (e.empty() || rank > e.size()) {
    throw awcc::OptionError(fmt::format("{} calibration runs cannot calibrate a {:g} % interval", e.size(),
                                        100 * (1 - alpha)),
                            "calibration");
  }
  return e[rank - 1];
}

// A row's conformity scores for the 50, 80, 95 % intervals of a forest's quantiles.
std::array<double, 3> interval_scores(const std::vector<double>& t, double target) {
  std::array<double, 3> e{};
  for (std::size_t k = 0; k < 3; ++k) e[k] = std::max(t[2 - k] - target, target - t[4 + k]);
  return e;
}

}  // namespace

namespace {

// The envelopes of trust rule (a) (model.hpp) from rows' shifts {velocity,
// Tu} and their groups: the group's rows, else the window band's, else all
// of them; too few even then, the model's own (its training targets').
void set_envelopes(Calibration& c, const CorrectionModel& model, const std::vector<int>& band,
                   const std::vector<int>& tu_band, const std::vector<std::array<double, 2>>& shifts) {
  auto envelope = [&](const std::function<bool(std::size_t)>& in, std::size_t q) {
    std::vector<double> e;
    for (std::size_t i = 0; i < shifts.size(); ++i)
      if (in(i)) e.push_back(shifts[i][q]);
    return envelope_of(std::move(e));
  };
  c.velocity_envelope.clear();
  c.turbulence_envelope.clear();
  const std::function<bool(std::size_t)> all = [](std::size_t) { return true; };
  if (!envelope(all, 0) || !envelope(all, 1)) {
    c.velocity_envelope = model.calibration.velocity_envelope;
    c.turbulence_envelope = model.calibration.turbulence_envelope;
    c.envelope_from_training = model.calibration.envelope_from_training;
    return;
  }
  c.envelope_from_training = false;
  for (std::size_t b = 0; b <= c.window_edges.size(); ++b) {
    const int w = static_cast<int>(b);
    for (std::size_t h = 0; h < c.tu_bands(); ++h) {
      const std::function<bool(std::size_t)> in_group = [&band, &tu_band, w, h](std::size_t i) {
        return band[i] == w && tu_band[i] == static_cast<int>(h);
      };
      const std::function<bool(std::size_t)> in_band = [&band, w](std::size_t i) { return band[i] == w; };
      for (std::size_t q = 0; q < 2; ++q) {
        auto e = envelope(in_group, q);
        if (!e) e = envelope(in_band, q);
        if (!e) e = envelope(all, q);
        (q == 0 ? c.velocity_envelope : c.turbulence_envelope).push_back(*e);
      }
    }
  }
}

// The FSCC forest's envelope from rows' truths (its target's shift from FSCC's velocity).
std::vector<std::array<double, 2>> fscc_envelope(const FsccForest& f, const std::vector<TrainingRow>& rows) {
  std::vector<double> shifts;
  for (const auto& r : rows) {
    const double v = r.features.fscc_velocity;
    shifts.push_back(to_target(f.form, r.true_velocity, v) - to_target(f.form, v, v));
  }
  const auto e = envelope_of(std::move(shifts));
  return e ? std::vector<std::array<double, 2>>{*e} : std::vector<std::array<double, 2>>{};
}

}  // namespace

Calibration calibrate(const CorrectionModel& model, const std::vector<TrainingRow>& rows,
                      const std::vector<std::int64_t>& window_edges, int threads,
                      const std::vector<double>& tu_edges) {
  std::vector<std::string> names;
  for (const auto& r : model.ranges) names.push_back(r.name);
  Calibration c;
  c.window_edges = window_edges;
  c.tu_edges = tu_edges;
  // Scores of each row: velocity then Tu, intervals 50, 80, 95 %; its
  // window band and Tu band (the Tu forest's median, as correct() finds it).
  std::vector<std::array<double, 6>> scores(rows.size());
  std::vector<int> band(rows.size()), tu_band(rows.size());
  // The truth's shift from the measurement (model.hpp, trust rule (a)): velocity, Tu.
  std::vector<std::array<double, 2>> shifts(rows.size());
  parallel_for(rows.size(), threads, [&](std::size_t i) {
    const auto& r = rows[i];
    const auto x = vector_of(r.features, names);
    for (int f = 0; f < 2; ++f) {
      const auto& forest = f == 0 ? model.velocity : model.turbulence_intensity;
      const auto form = f == 0 ? model.velocity_form : model.turbulence_form;
      const double target = f == 0 ? to_target(form, r.true_velocity, r.features.velocity)
                                   : to_target(form, r.true_turbulence_intensity, r.features.turbulence_intensity);
      const auto t = forest.quantiles(x, correction_levels);
      const auto e = interval_scores(t, target);
      const double measured = f == 0 ? r.features.velocity : r.features.turbulence_intensity;
      shifts[i][static_cast<std::size_t>(f)] = target - to_target(form, measured, measured);
      for (std::size_t k = 0; k < 3; ++k) scores[i][static_cast<std::size_t>(3 * f) + k] = e[k];
      if (f == 1) tu_band[i] = c.tu_band(from_target(form, t[3], r.features.turbulence_intensity));
    }
    band[i] = c.band(r.features.windows_accepted);
  });
  // The offsets of the rows that `in` admits.
  auto offsets = [&](const std::function<bool(std::size_t)>& in, std::size_t column0) {
    std::array<double, 3> q{};
    for (std::size_t k = 0; k < 3; ++k) {
      std::vector<double> e;
      for (std::size_t i = 0; i < rows.size(); ++i)
        if (in(i)) e.push_back(scores[i][column0 + k]);
      q[k] = conformal_offset(std::move(e), calibration_alpha[k]);
    }
    return q;
  };
  // A group with too few calibration runs (fewer than 1/alpha for the 95 %
  // interval, with margin) takes its window band's offsets; a window band
  // with too few, the pooled ones.
  constexpr std::int64_t least = 50;
  for (std::size_t b = 0; b <= window_edges.size(); ++b) {
    const int w = static_cast<int>(b);
    const auto in_band = std::count(band.begin(), band.end(), w);
    for (std::size_t h = 0; h < c.tu_bands(); ++h) {
      std::int64_t in_group = 0;
      for (std::size_t i = 0; i < rows.size(); ++i) in_group += band[i] == w && tu_band[i] == static_cast<int>(h);
      std::function<bool(std::size_t)> in = [](std::size_t) { return true; };
      if (in_group >= least) {
        in = [&band, &tu_band, w, h](std::size_t i) { return band[i] == w && tu_band[i] == static_cast<int>(h); };
      } else if (in_band >= least) {
        in = [&band, w](std::size_t i) { return band[i] == w; };
      }
      c.velocity.push_back(offsets(in, 0));
      c.turbulence_intensity.push_back(offsets(in, 3));
    }
  }
  set_envelopes(c, model, band, tu_band, shifts);
  return c;
}

namespace {

// The runs' split: held out first, then the calibration runs, then the
// training runs, in the order of a hash of the run (independent of file order).
struct Split {
  std::vector<TrainingRow> held_out, calibration, training;
};

}  // namespace

double duration_cap(const std::vector<TrainingRow>& rows) {
  std::vector<double> d;
  d.reserve(rows.size());
  for (const auto& r : rows)
    if (r.features.duration > 0.0) d.push_back(r.features.duration);
  if (d.empty()) return 0.0;
  std::sort(d.begin(), d.end());
  const auto above = static_cast<std::size_t>(std::floor(duration_saturation_share * static_cast<double>(d.size())));
  return d[d.size() - 1 - above];
}

namespace {

// The rows as the forests see them: durations above the cap at the cap.
std::vector<TrainingRow> with_saturated_durations(std::vector<TrainingRow> rows) {
  const double cap = duration_cap(rows);
  for (auto& r : rows) {
    r.features.duration = std::min(r.features.duration, cap);
    if (r.unweighted) r.unweighted->duration = std::min(r.unweighted->duration, cap);
  }
  return rows;
}

Split split_runs(std::vector<TrainingRow> rows, const TrainOptions& o) {
  auto key = [&](const TrainingRow& r) { return mix64(o.seed ^ mix64(static_cast<std::uint64_t>(r.run) ^ mix64(r.study))); };
  std::sort(rows.begin(), rows.end(), [&](const TrainingRow& a, const TrainingRow& b) {
    const auto ha = key(a), hb = key(b);
    if (ha != hb) return ha < hb;
    return a.study != b.study ? a.study < b.study : a.run < b.run;
  });
  const auto held = static_cast<std::size_t>(std::llround(o.held_out * static_cast<double>(rows.size())));
  const auto calibrating = static_cast<std::size_t>(std::llround(o.calibration * static_cast<double>(rows.size() - held)));
  const auto at = [&](std::size_t i) { return rows.begin() + static_cast<std::ptrdiff_t>(i); };
  return {{rows.begin(), at(held)}, {at(held), at(held + calibrating)}, {at(held + calibrating), rows.end()}};
}

// The FSCC forest's scores on held-out rows (all with an FSCC velocity, or
// those AWCC cannot serve: where the forest is applied).
FsccScores score_fscc(const CorrectionModel& scorer, const std::vector<TrainingRow>& held_out, bool unserved_only) {
  FsccScores sc;
  std::vector<double> abs_raw, abs_corrected;
  double sq_raw = 0.0, sq_corrected = 0.0;
  for (const auto& r : held_out) {
    if (unserved_only && r.awcc_served) continue;
    const auto c = scorer.correct_fscc(r.features);
    if (!c.velocity) {
      ++sc.out_of_range;
      continue;
    }
    sc.untrusted += c.status == CorrectionStatus::untrusted;
    sc.outside_envelope += c.outside_envelope;
    sc.multimodal += c.multimodal;
    sc.one_sample_lag += c.one_sample_lag;
    const double raw = r.features.fscc_velocity / r.true_velocity - 1.0;
    const double corrected = c.velocity->median() / r.true_velocity - 1.0;
    sq_raw += raw * raw;
    sq_corrected += corrected * corrected;
    abs_raw.push_back(std::fabs(raw));
    abs_corrected.push_back(std::fabs(corrected));
    const auto& q = c.velocity->quantiles;
    sc.coverage80 += q[1] <= r.true_velocity && r.true_velocity <= q[5];
    sc.coverage95 += q[0] <= r.true_velocity && r.true_velocity <= q[6];
    ++sc.rows;
  }
  if (sc.rows > 0) {
    const auto n = static_cast<double>(sc.rows);
    sc.rmse_raw = std::sqrt(sq_raw / n);
    sc.rmse_corrected = std::sqrt(sq_corrected / n);
    sc.median_abs_raw = awcc::median(abs_raw);
    sc.median_abs_corrected = awcc::median(abs_corrected);
    sc.coverage80 /= n;
    sc.coverage95 /= n;
  }
  return sc;
}

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
    std::vector<std::array<double, 3>> scores(calibrating_rows.size());
    parallel_for(calibrating_rows.size(), o.threads, [&](std::size_t i) {
      const auto& r = calibrating_rows[i];
      scores[i] = interval_scores(f.velocity.quantiles(vector_of(r.features, names), correction_levels),
                                  to_target(f.form, r.true_velocity, r.features.fscc_velocity));
    });
    std::array<double, 3> q{};
    for (std::size_t k = 0; k < 3; ++k) {
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
      "windows); trained on {}, {} set aside to calibrate the intervals, {} held out (seed {}). Velocity: target {}, {} trees, min leaf {}, {} features per "
      "split. Tu: target {}, {} trees, min leaf {}, {} features per split. Held out: velocity RMSE {:.2f} % raw, "
      "{:.2f} % corrected, 80/95 % coverage {:.1f}/{:.1f} %; Tu RMSE {:.4f} raw, {:.4f} corrected, 80/95 % coverage "
      "{:.1f}/{:.1f} %.",
      awcc::version, sources, fmt::join(set.generator_versions, " and "), o.feature_set, fmt::join(names, ", "),
      describe(set.processing),
      set.processing_assumed ? " (assumed: the sweep CSVs do not record it)" : "", set.total, set.rows.size(), set.excluded_error, set.excluded_undefined,
      set.excluded_windows, o.min_windows, split.training.size(), split.calibration.size(), split.held_out.size(), o.seed,
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

// The rows and, after each that has one, its unweighted twin (the same run's
// windows with unweighted moments, feature awcc_unweighted 1).
std::vector<TrainingRow> with_unweighted_twins(const std::vector<TrainingRow>& rows) {
  std::vector<TrainingRow> out;
  out.reserve(2 * rows.size());
  for (const auto& r : rows) {
    out.push_back(r);
    if (!r.unweighted) continue;
    TrainingRow twin = r;
    twin.features = *r.unweighted;
    twin.unweighted.reset();
    out.push_back(std::move(twin));
  }
  return out;
}

}  // namespace

std::vector<TrainingRow> as_peer_rows(std::vector<TrainingRow> rows) {
  for (auto& r : rows) {
    for (auto* f : {&r.features, r.unweighted ? &*r.unweighted : nullptr}) {
      if (!f) continue;
      f->fs = 0.0;
      f->duration = 0.0;
      f->windows_accepted = -1;
      f->windows_total = -1;
      f->time_scale_ratio = 0.0;
    }
  }
  return rows;
}

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
// set; docs/validation.md), whose records are also at 500 kHz.
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
  Split split = split_runs(set.rows, o);
  split.training = with_saturated_durations(std::move(split.training));
  const std::size_t runs = set.rows.size();
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

  TrainResult result;
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

std::string scores_report(const HeldOutScores& h, const std::vector<HeldOutPrediction>& predictions) {
  std::string out;
  auto line = [&out](const std::string& s) { out += s + "\n"; };
  line("                         raw AWCC    corrected median");
  line(fmt::format("  velocity RMSE          {:7.3f} %   {:7.3f} %", 100 * h.velocity_rmse_raw, 100 * h.velocity_rmse_corrected));
  line(fmt::format("  velocity median |err|  {:7.3f} %   {:7.3f} %", 100 * h.velocity_median_abs_raw,
                   100 * h.velocity_median_abs_corrected));
  line(fmt::format("  velocity mean error    {:7.3f} %   {:7.3f} %", 100 * h.velocity_bias_raw, 100 * h.velocity_bias_corrected));
  line(fmt::format("  Tu RMSE                {:7.4f}     {:7.4f}", h.tu_rmse_raw, h.tu_rmse_corrected));
  line(fmt::format("  Tu median |err|        {:7.4f}     {:7.4f}", h.tu_median_abs_raw, h.tu_median_abs_corrected));
  line(fmt::format("  Tu mean error          {:7.4f}     {:7.4f}", h.tu_bias_raw, h.tu_bias_corrected));
  line(fmt::format("  coverage 80 % / 95 %   velocity {:.1f} / {:.1f} %, Tu {:.1f} / {:.1f} %", 100 * h.velocity_coverage80,
                   100 * h.velocity_coverage95, 100 * h.tu_coverage80, 100 * h.tu_coverage95));
  const auto table = scores_by_band(predictions);
  if (!table.empty()) {
    line("Held-out runs by band: errors raw -> corrected (velocity relative, Tu absolute) and coverage (nominal 80 / 95 %):");
    line("  band                          runs  corrected   u RMSE raw -> corr    u median|err|      Tu RMSE        "
         "Tu median|err|    u 80 %  95 %   Tu 80 %  95 %");
    for (const auto& b : table) {
      line(fmt::format("  {:<28} {:>6} {:>9}   {:7.2f} -> {:6.2f} %   {:5.2f} -> {:5.2f} %   {:.4f} -> {:.4f}   "
                       "{:.4f} -> {:.4f}   {:5.1f} {:5.1f}   {:6.1f} {:5.1f}",
                       b.band, b.runs, b.rows, 100 * b.velocity_rmse_raw, 100 * b.velocity_rmse_corrected,
                       100 * b.velocity_median_abs_raw, 100 * b.velocity_median_abs_corrected, b.tu_rmse_raw,
                       b.tu_rmse_corrected, b.tu_median_abs_raw, b.tu_median_abs_corrected, 100 * b.velocity80,
                       100 * b.velocity95, 100 * b.tu80, 100 * b.tu95));
    }
  }
  return out;
}

std::string TrainResult::report() const {
  std::string out = model.provenance + "\n\n";
  auto line = [&out](const std::string& s) { out += s + "\n"; };
  if (!cv.empty()) {
    line("Cross-validation (mean pinball loss over the correction levels; velocity relative to the truth):");
    line("  target                form        min_leaf  features/split  pinball");
    for (const auto& e : cv) {
      line(fmt::format("  {:<21} {:<11} {:>8}  {:>14}  {:.6f}", e.target, to_string(e.form), e.min_leaf,
                       e.features_per_split, e.pinball));
    }
    line(fmt::format("  ({:.1f} s)", seconds_cv));
  }
  const auto& h = held_out;
  line(fmt::format("Held out: {} runs ({} outside the training ranges, not scored; {} of the scored untrusted by the "
                   "trust rules: {} outside the envelope, {} multimodal, {} at a lag of one sample, {} at a chance "
                   "yield); training {} runs in {:.2f} s",
                   h.rows, h.out_of_range, h.untrusted, h.outside_envelope, h.multimodal, h.one_sample_lag,
                   h.chance_yield, training_rows, seconds_train));
  out += scores_report(h, predictions);
  if (model.reduced) {
    const auto& r = reduced_held_out;
    line(fmt::format("Reduced model (rows without fs, duration or windows: peers' files), on the same held-out runs "
                     "with those features removed: {} runs scored ({} outside the training ranges; {} untrusted)",
                     r.rows, r.out_of_range, r.untrusted));
    out += scores_report(r, reduced_predictions);
    line(fmt::format("  pinball loss: velocity {:.6f} (extended {:.6f}), Tu {:.6f} (extended {:.6f})",
                     r.velocity_pinball, h.velocity_pinball, r.tu_pinball, h.tu_pinball));
  }
  if (!learning_curve.empty()) {
    line("Learning curve (held-out scores against training runs):");
    line("  (gain: paired decrease of the pinball loss from the previous point, +/- its standard error)");
    line("  runs    velocity RMSE   velocity pinball (gain)              Tu RMSE   Tu pinball (gain)");
    for (const auto& p : learning_curve) {
      line(fmt::format("  {:>6}  {:9.3f} %   {:.6f} ({:+.6f} +/- {:.6f})   {:8.4f}   {:.6f} ({:+.6f} +/- {:.6f})",
                       p.training_rows, 100 * p.scores.velocity_rmse_corrected, p.scores.velocity_pinball,
                       p.velocity_gain, p.velocity_gain_se, p.scores.tu_rmse_corrected, p.scores.tu_pinball, p.tu_gain,
                       p.tu_gain_se));
    }
  }
  return out;
}

namespace {

struct Band {
  std::string name;
  std::function<bool(const HeldOutPrediction&)> holds;
};

// The bands of the held-out tables: true Tu (the bands, and the
// campaign's top, 0.35-0.45, apart: a band at the edge of the drawn range is
// where quantile forests cover worst), the model's Tu, accepted windows,
// sampling rate. Plain copies of the ends: lambdas capture them (clang 14
// cannot capture bindings).
std::vector<Band> held_out_bands() {
  std::vector<Band> bands{{"all", [](const HeldOutPrediction&) { return true; }}};
  for (const auto& band : std::vector<std::pair<double, double>>{{0, 0.1}, {0.1, 0.2}, {0.2, 0.3}, {0.3, 0.35}, {0.35, 0.45}}) {
    const double lo = band.first, hi = band.second;
    bands.push_back({fmt::format("true Tu {:g}-{:g}", lo, hi), [lo, hi](const HeldOutPrediction& p) {
                       return p.row.true_turbulence_intensity >= lo && p.row.true_turbulence_intensity < hi;
                     }});
  }
  // The model's Tu (its corrected median): what a lab sees, and what the
  // calibration's Tu bands are made of.
  for (const auto& band : std::vector<std::pair<double, double>>{{0, 0.1}, {0.1, 0.2}, {0.2, 0.3}, {0.3, 1e300}}) {
    const double lo = band.first, hi = band.second;
    bands.push_back({hi > 1e299 ? fmt::format("model Tu {:g}+", lo) : fmt::format("model Tu {:g}-{:g}", lo, hi),
                     [lo, hi](const HeldOutPrediction& p) {
                       if (!p.correction.turbulence_intensity) return false;
                       const double t = p.correction.turbulence_intensity->median();
                       return t >= lo && t < hi;
                     }});
  }
  for (const auto& band : std::vector<std::pair<std::int64_t, std::int64_t>>{{10, 30}, {30, 100}, {100, 1LL << 62}}) {
    const std::int64_t lo = band.first, hi = band.second;
    bands.push_back({hi > (1LL << 61) ? fmt::format("windows {}+", lo) : fmt::format("windows {}-{}", lo, hi - 1),
                     [lo, hi](const HeldOutPrediction& p) {
                       return p.row.features.windows_accepted >= lo && p.row.features.windows_accepted < hi;
                     }});
  }
  for (const auto& band : std::vector<std::pair<double, double>>{{0, 50e3}, {50e3, 200e3}, {200e3, 1e300}}) {
    const double lo = band.first, hi = band.second;
    bands.push_back({hi > 1e299 ? fmt::format("fs {:g} kHz+", lo / 1e3) : fmt::format("fs {:g}-{:g} kHz", lo / 1e3, hi / 1e3),
                     [lo, hi](const HeldOutPrediction& p) { return p.row.features.fs > lo && p.row.features.fs <= hi; }});
  }
  // The record's length (issue 33: the coverage by duration, to 1,800 s and
  // beyond the training records, where the duration is held).
  for (const auto& band : std::vector<std::pair<double, double>>{{0, 60}, {60, 300}, {300, 600}, {600, 1800}, {1800, 1e300}}) {
    const double lo = band.first, hi = band.second;
    bands.push_back({hi > 1e299 ? fmt::format("duration {:g} s+", lo) : fmt::format("duration {:g}-{:g} s", lo, hi),
                     [lo, hi](const HeldOutPrediction& p) {
                       return p.row.features.duration > lo && p.row.features.duration <= hi;
                     }});
  }
  // How AWCC's moments were taken (a model with the weighting feature
  // scores each run both ways).
  for (const int unweighted : {0, 1}) {
    bands.push_back({unweighted ? "unweighted moments" : "duration-weighted moments",
                     [unweighted](const HeldOutPrediction& p) { return p.row.features.awcc_unweighted == unweighted; }});
  }
  return bands;
}

}  // namespace

std::vector<BandScores> scores_by_band(const std::vector<HeldOutPrediction>& predictions) {
  std::vector<BandScores> out;
  for (const auto& b : held_out_bands()) {
    BandScores c;
    c.band = b.name;
    std::vector<double> u_raw, u_corrected, t_raw, t_corrected;
    double u_sq_raw = 0.0, u_sq_corrected = 0.0, t_sq_raw = 0.0, t_sq_corrected = 0.0;
    for (const auto& p : predictions) {
      if (!b.holds(p)) continue;
      ++c.runs;
      if (!p.correction.velocity || !p.correction.turbulence_intensity) continue;  // untrusted rows scored too
      const auto& u = p.correction.velocity->quantiles;
      const auto& t = p.correction.turbulence_intensity->quantiles;
      const double uu = p.row.true_velocity, tt = p.row.true_turbulence_intensity;
      const double ur = p.row.features.velocity / uu - 1.0, uc = p.correction.velocity->median() / uu - 1.0;
      const double tr = p.row.features.turbulence_intensity - tt, tc = p.correction.turbulence_intensity->median() - tt;
      u_sq_raw += ur * ur, u_sq_corrected += uc * uc, t_sq_raw += tr * tr, t_sq_corrected += tc * tc;
      u_raw.push_back(std::fabs(ur)), u_corrected.push_back(std::fabs(uc));
      t_raw.push_back(std::fabs(tr)), t_corrected.push_back(std::fabs(tc));
      c.velocity80 += u[1] <= uu && uu <= u[5];
      c.velocity95 += u[0] <= uu && uu <= u[6];
      c.tu80 += t[1] <= tt && tt <= t[5];
      c.tu95 += t[0] <= tt && tt <= t[6];
      ++c.rows;
    }
    if (c.rows == 0) continue;  // a band the runs do not reach (fs bands of a 500 kHz campaign)
    const auto n = static_cast<double>(c.rows);
    c.velocity80 /= n, c.velocity95 /= n, c.tu80 /= n, c.tu95 /= n;
    c.velocity_rmse_raw = std::sqrt(u_sq_raw / n);
    c.velocity_rmse_corrected = std::sqrt(u_sq_corrected / n);
    c.tu_rmse_raw = std::sqrt(t_sq_raw / n);
    c.tu_rmse_corrected = std::sqrt(t_sq_corrected / n);
    c.velocity_median_abs_raw = awcc::median(u_raw);
    c.velocity_median_abs_corrected = awcc::median(u_corrected);
    c.tu_median_abs_raw = awcc::median(t_raw);
    c.tu_median_abs_corrected = awcc::median(t_corrected);
    out.push_back(c);
  }
  return out;
}

std::vector<HeldOutPrediction> corrected_by_both(const std::vector<HeldOutPrediction>& predictions,
                                                 const std::vector<HeldOutPrediction>& other) {
  if (predictions.size() != other.size()) {
    throw std::invalid_argument("corrected_by_both: the two prediction sets are not of the same runs");
  }
  std::vector<HeldOutPrediction> out;
  for (std::size_t i = 0; i < predictions.size(); ++i) {
    if (predictions[i].row.run != other[i].row.run || predictions[i].row.study != other[i].row.study) {
      throw std::invalid_argument("corrected_by_both: the two prediction sets are not of the same runs");
    }
    if (predictions[i].correction.velocity && other[i].correction.velocity) out.push_back(predictions[i]);
  }
  return out;
}

std::string comparison_report(const std::vector<HeldOutPrediction>& mine, const std::vector<HeldOutPrediction>& other,
                              const std::string& other_name) {
  const auto all = scores_by_band(mine);
  const auto theirs = scores_by_band(other);
  const auto both_mine = scores_by_band(corrected_by_both(mine, other));
  const auto both_theirs = scores_by_band(corrected_by_both(other, mine));
  auto find = [](const std::vector<BandScores>& t, const std::string& band) -> const BandScores* {
    for (const auto& b : t)
      if (b.band == band) return &b;
    return nullptr;
  };
  std::string out = fmt::format(
      "Against {} on the same held-out runs: errors on the runs both models correct (raw = AWCC's; velocity "
      "relative, Tu absolute):\n"
      "  band                          runs  corrected: this  other   u RMSE raw / other / this   "
      "u median|err| raw / other / this   Tu RMSE raw / other / this   Tu median|err| raw / other / this\n",
      other_name);
  std::string coverage =
      "Coverage on the same runs (nominal 80 / 95 %), other / this:\n"
      "  band                          both     u 80 %         u 95 %         Tu 80 %        Tu 95 %\n";
  for (const auto& a : all) {
    // Each model reads its own Tu, so a band of it would hold other runs for
    // each: bands of the model's Tu are left out of the comparison.
    if (a.band.starts_with("model Tu")) continue;
    const auto* t = find(theirs, a.band);
    const auto* bm = find(both_mine, a.band);
    const auto* bt = find(both_theirs, a.band);
    out += fmt::format("  {:<28} {:>6} {:>16} {:>6}", a.band, a.runs, a.rows, t ? t->rows : 0);
    if (bm && bt) {
      out += fmt::format("   {:6.2f} / {:6.2f} / {:6.2f} %   {:6.2f} / {:6.2f} / {:6.2f} %       "
                         "{:.4f} / {:.4f} / {:.4f}   {:.4f} / {:.4f} / {:.4f}",
                         100 * bt->velocity_rmse_raw, 100 * bt->velocity_rmse_corrected,
                         100 * bm->velocity_rmse_corrected, 100 * bt->velocity_median_abs_raw,
                         100 * bt->velocity_median_abs_corrected, 100 * bm->velocity_median_abs_corrected,
                         bt->tu_rmse_raw, bt->tu_rmse_corrected, bm->tu_rmse_corrected, bt->tu_median_abs_raw,
                         bt->tu_median_abs_corrected, bm->tu_median_abs_corrected);
      coverage += fmt::format("  {:<28} {:>6}   {:5.1f} / {:5.1f}  {:5.1f} / {:5.1f}  {:5.1f} / {:5.1f}  {:5.1f} / {:5.1f}\n",
                              a.band, bm->rows, 100 * bt->velocity80, 100 * bm->velocity80, 100 * bt->velocity95,
                              100 * bm->velocity95, 100 * bt->tu80, 100 * bm->tu80, 100 * bt->tu95, 100 * bm->tu95);
    }
    out += "\n";
  }
  return out + coverage;
}

std::string predictions_csv(const std::vector<HeldOutPrediction>& predictions) {
  std::string out = "run,velocity,turbulence_intensity,void_fraction,d32,dx,dy,np,windows_accepted,fs,duration,"
                    "awcc_unweighted,true_velocity,true_turbulence_intensity,in_range,status,turbulence_corrected";
  for (const char* q : {"velocity", "turbulence_intensity"}) {
    for (const char* l : correction_level_names) out += fmt::format(",corrected_{}_q{}", q, l);
  }
  out += "\n";
  for (const auto& p : predictions) {
    const auto& f = p.row.features;
    out += fmt::format("{},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{},{:.10g},{:.10g},{},{:.10g},{:.10g},{},{},{}",
                       p.row.run, f.velocity, f.turbulence_intensity, f.void_fraction, f.d32, f.dx, f.dy, f.np,
                       f.windows_accepted, f.fs, f.duration, f.awcc_unweighted, p.row.true_velocity,
                       p.row.true_turbulence_intensity,
                       p.correction.corrected() ? 1 : 0, to_string(p.correction.status),
                       p.correction.turbulence_corrected() ? 1 : 0);
    for (const auto* q : {&p.correction.velocity, &p.correction.turbulence_intensity}) {
      for (std::size_t k = 0; k < correction_levels.size(); ++k) {
        out += *q ? fmt::format(",{:.10g}", (*q)->quantiles[k]) : std::string(",");
      }
    }
    out += "\n";
  }
  return out;
}

std::string learning_curve_csv(const std::vector<LearningPoint>& curve) {
  std::string out = "training_runs,held_out_runs,velocity_rmse_raw,velocity_rmse_corrected,velocity_pinball,"
                    "velocity_coverage80,velocity_coverage95,tu_rmse_raw,tu_rmse_corrected,tu_pinball,tu_coverage80,"
                    "tu_coverage95,velocity_gain,velocity_gain_se,tu_gain,tu_gain_se\n";
  for (const auto& p : curve) {
    const auto& s = p.scores;
    out += fmt::format("{},{},{:.8g},{:.8g},{:.8g},{:.6g},{:.6g},{:.8g},{:.8g},{:.8g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n",
                       p.training_rows, s.rows, s.velocity_rmse_raw, s.velocity_rmse_corrected, s.velocity_pinball,
                       s.velocity_coverage80, s.velocity_coverage95, s.tu_rmse_raw, s.tu_rmse_corrected, s.tu_pinball,
                       s.tu_coverage80, s.tu_coverage95, p.velocity_gain, p.velocity_gain_se, p.tu_gain, p.tu_gain_se);
  }
  return out;
}

}  // namespace correction
