#pragma once
// pdp bench: error against cost, as a lab chooses a method and a record. Five
// fixed scenes (the base case and hard ones), each synthesised with N seeds;
// on each, every method and setting (FSCC; AWCC on the binary signals by the
// interval and FFT paths, and on the raw voltage; the quantile-forest
// correction) over record durations, Np and sampling rates, its processing
// cost (CPU seconds of the method alone) and its estimates against the truth.
// One CSV row per seed and setting; tools/plot_study.py aggregates them (RMS
// error, bias, spread, the Pareto front) and draws the figure.

#include <CLI/CLI.hpp>
#include <string>

#include "command.hpp"

namespace pdp {

struct BenchOptions {
  std::string output;           ///< CSV, one row per scene, seed and setting
  int seeds = 10;               ///< seeds per scene (RMS, bias and spread are over these)
  std::uint64_t first_seed = 1; ///< seeds first_seed .. first_seed + seeds - 1
  std::string scenes = "base,high-tu,small-bubbles,low-c,short-T";
  std::string durations = "10s,30s,60s,150s,300s,600s";  ///< record lengths at 500 kHz, Np = 10
  std::string duration = "60s"; ///< record length of the Np, fs and raw-voltage settings
  std::string correct;          ///< correction model (.qrf): adds corrected AWCC rows
  int threads = 0;              ///< worker threads (0 = all cores)
  bool quick = false;           ///< short records, two seeds, few settings (tests)
};

void setup_bench(CLI::App& app, Command& command, BenchOptions& options);
int run_bench(const BenchOptions& options);

}  // namespace pdp
