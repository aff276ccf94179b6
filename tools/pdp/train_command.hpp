#pragma once
// pdp train: the bias-correction model (two quantile regression forests) from
// pdp sweep CSVs, with k-fold cross-validation of its hyperparameters and a
// report on held-out runs.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "command.hpp"

namespace pdp {

struct TrainCommandOptions {
  std::vector<std::string> sweeps;  ///< pdp sweep CSVs (shards may be given together)
  std::string output;               ///< model file (.qrf)
  int trees = 100;
  std::int64_t min_windows = 100;
  double held_out = 0.2;
  int folds = 5;
  int cv_trees = 50;
  std::string min_leaf_grid = "1,2,3,5,10,20";
  std::string features_per_split_grid = "2,3,5,7";
  std::uint64_t seed = 1;
  int threads = 0;
  std::string predictions;          ///< held-out predictions CSV
  std::string learning_curve;       ///< learning curve CSV
  std::string report;               ///< the report as a text file (also on stdout)
};

void setup_train(CLI::App& app, Command& command, TrainCommandOptions& options);
int run_train(const TrainCommandOptions& options);

}  // namespace pdp
