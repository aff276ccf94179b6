#pragma once
// pdp sweep: a grid or Monte Carlo study over synthetic scenes, on all cores,
// into an append-only CSV that an interrupted sweep resumes.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

#include "command.hpp"
#include "scene_cli.hpp"

namespace pdp {

struct SweepOptions {
  std::string study;          ///< sweep TOML file
  std::string output;         ///< CSV (appended; resumed when it holds rows of this study)
  int threads = 0;            ///< 0 = all cores
  std::string shard;          ///< "i/n": this process runs the runs with index % n == i
  std::int64_t first_runs = 0;  ///< run only the runs with index below this; 0 = every run
  OptionSet methods;          ///< AWCC/FSCC settings for every run (np: unless the study sets it)
};

void setup_sweep(CLI::App& app, Command& command, SweepOptions& options);
int run_sweep(const SweepOptions& options);

}  // namespace pdp
