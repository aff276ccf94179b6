#pragma once
// pdp train: the bias-correction model (two quantile regression forests) from
// pdp sweep CSVs, with k-fold cross-validation of its hyperparameters and a
// report on held-out runs.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli_options.hpp"
#include "command.hpp"

namespace pdp {

struct TrainCommandOptions {
  std::vector<std::string> sweeps;  ///< pdp sweep CSVs (shards may be given together)
  std::string output;               ///< model file (.qrf)
  OptionSet training;               ///< correction::training_option_fields()
  std::string predictions;          ///< held-out predictions CSV
  std::string learning_curve;       ///< learning curve CSV
  std::string report;               ///< the report as a text file (also on stdout)
  std::string compare_model;        ///< another model scored on the same held-out runs
  std::string envelope_of;          ///< a trained model whose trust envelopes the sweeps measure (no training)
};

void setup_train(CLI::App& app, Command& command, TrainCommandOptions& options);
int run_train(const TrainCommandOptions& options);

}  // namespace pdp
