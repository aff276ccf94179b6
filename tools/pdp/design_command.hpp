#pragma once
// pdp design: ranks probe geometries and settings (dx, dy, Np, fs, record
// length) for the lab's own flow by simulating it (study/design.hpp says how).
// A sweep underneath: threads, resume, shards and MPI as pdp sweep.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "command.hpp"

namespace pdp {

struct DesignOptions {
  std::string config;               ///< the design: conditions, candidates (TOML)
  std::string output;               ///< the ranked CSV
  std::string report;               ///< HTML page (error maps), optional
  std::string model;                ///< correction model; overrides the file's [design] model
  std::vector<std::string> runs;    ///< runs CSVs (the first is appended to); default OUTPUT.runs.csv
  int threads = 0;                  ///< 0 = all cores
  std::string shard;                ///< "i/n"
};

void setup_design(CLI::App& app, Command& command, DesignOptions& options);
int run_design(const DesignOptions& options);

}  // namespace pdp
