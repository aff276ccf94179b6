#pragma once
// pdp sweep: a grid or Monte Carlo study over synthetic scenes, on all cores,
// into an append-only CSV that an interrupted sweep resumes.

#include <CLI/CLI.hpp>
#include <string>

#include "scene_cli.hpp"

namespace pdp {

struct SweepOptions {
  std::string study;          ///< sweep TOML file
  std::string output;         ///< CSV (appended; resumed when it holds rows of this study)
  int threads = 0;            ///< 0 = all cores
  std::string shard;          ///< "i/n": this process runs the runs with index % n == i
  MethodCli methods;          ///< AWCC/FSCC settings (np comes from the study)
};

CLI::App* setup_sweep(CLI::App& app, SweepOptions& options);
int run_sweep(const SweepOptions& options);

}  // namespace pdp
