#pragma once
// pdp correct: adds the bias correction (median and quantiles of the true
// velocity and turbulence intensity, METHOD.md 7) to a pdp process JSON or a
// profile CSV. Rows outside the model's training ranges are flagged and left
// uncorrected. A profile (every row with its position) gets its flow
// quantities anew, with the corrected velocities (awcc/profile_flow.hpp):
// the JSON's "flow", and the summary on stdout when the output is a file.

#include <CLI/CLI.hpp>
#include <string>

#include "cli_options.hpp"
#include "command.hpp"
#include "mat_cli.hpp"

namespace pdp {

struct CorrectOptions {
  std::string input;    ///< pdp process JSON or profile CSV
  std::string model;    ///< .qrf model file
  std::string output;   ///< output file; empty = stdout
  std::string dx, dy;   ///< tip separations where the input lacks them (units allowed)
  int np = 0;           ///< AWCC particles per window where the input lacks it; 0 = not given
  std::string fs;       ///< sampling rate where the input lacks it (units allowed)
  std::string duration; ///< record length where the input lacks it (units allowed)
  std::string weighting; ///< AWCC's moments where the input does not record them: duration | none; empty = not known
  OptionSet flow;       ///< a profile's flow quantities (awcc/profile_flow.hpp)
  MatOption mat;        ///< --mat, --mat-v73 (a JSON input)
};

void setup_correct(CLI::App& app, Command& command, CorrectOptions& options);
int run_correct(const CorrectOptions& options);

}  // namespace pdp
