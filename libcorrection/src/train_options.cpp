// The training's options (TrainOptions): their one declaration and validation.

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

using awcc::split_cells;

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

}  // namespace correction
