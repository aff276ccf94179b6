#pragma once
// pdp validate: synthesise a scene in memory, process it with FSCC and AWCC,
// and compare every estimate with the truth; --repeat N over N seeds.

#include <CLI/CLI.hpp>

#include "command.hpp"
#include "mat_cli.hpp"
#include "scene_cli.hpp"

namespace pdp {

struct ValidateOptions {
  SceneCli scene;
  OptionSet methods;
  OptionSet bubbles;        ///< event detection's and the multi-tip solvers' options (a probe of four or more tips)
  int repeat = 1;           ///< seeds (run i uses a seed derived from the scene seed and i)
  std::string json;         ///< JSON output file
  MatOption mat;            ///< --mat, --mat-v73: the JSON's content as MATLAB variables
  std::string profile;      ///< a synthetic profile's file (study/profile.hpp): every profile quantity against its truth
  std::string correct;      ///< with --profile: the correction model applied to every position
  OptionSet flow;           ///< the profile quantities' options (but the discharge, which the truth gives)
};

void setup_validate(CLI::App& app, Command& command, ValidateOptions& options);
int run_validate(const ValidateOptions& options);

}  // namespace pdp
