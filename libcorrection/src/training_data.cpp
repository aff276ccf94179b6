// Feature building of the training (training_steps.hpp): the runs' feature
// vectors and targets in the forests' order, their predictions and losses.

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

namespace detail {

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

}  // namespace detail

}  // namespace correction
