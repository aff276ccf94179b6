#pragma once
// pdp score: a trained correction model scored on sweep runs it was not
// trained on (another seed of its distribution, another generator version, a
// foreign simulator's conventions): every run is held out, nothing is
// trained. The scores are the training report's, band by band.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli_options.hpp"
#include "command.hpp"

namespace pdp {

struct ScoreOptions {
  std::string model;                ///< .qrf model file
  std::vector<std::string> sweeps;  ///< pdp sweep CSVs
  std::string predictions;          ///< the predictions as CSV
  std::string report;               ///< the report as a text file (also on stdout)
  int threads = 0;                  ///< worker threads (0 = all cores)
  std::string truth = "realised";   ///< realised | imposed (correction::TruthKind)
  /// Score runs processed otherwise than the model's training data (another
  /// tool's AWCC conventions, issue 33); the report names the difference.
  bool other_processing = false;
  /// Score the runs as a peer's file states them (correction::as_peer_rows):
  /// the reduced forest's scores.
  bool as_peer_rows = false;
};

void setup_score(CLI::App& app, Command& command, ScoreOptions& options);
int run_score(const ScoreOptions& options);

}  // namespace pdp
