#pragma once
// pdp bench: error against run time. A fixed set of scenes (the base case and
// hard ones), every method and setting timed (median of N runs) and scored
// against the truth, into a CSV that tools/plot_study.py draws.

#include <CLI/CLI.hpp>
#include <string>

#include "command.hpp"

namespace pdp {

struct BenchOptions {
  std::string output;          ///< CSV
  int repeat = 3;              ///< timings per setting (median)
  std::string scenes = "base,high-tu,small-bubbles,low-c,short-T";
  std::string duration = "30s"; ///< record length of the method and Np settings (a time with its unit)
  bool quick = false;          ///< short records and fewer settings (tests)
};

void setup_bench(CLI::App& app, Command& command, BenchOptions& options);
int run_bench(const BenchOptions& options);

}  // namespace pdp
