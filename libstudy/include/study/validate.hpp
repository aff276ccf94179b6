#pragma once
// One scene synthesised and processed N times with derived seeds (pdp
// validate): every run scored against its truth (study/run.hpp), and each
// error's mean and 95 % interval over the runs.

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "study/run.hpp"
#include "study/tasks.hpp"

namespace study {

/// Mean and 95 % interval (Student t) of a sample of errors.
struct Summary95 {
  std::int64_t count = 0;
  double mean = 0.0, lower = 0.0, upper = 0.0;
};
Summary95 summarise95(const std::vector<double>& values);

/// `repeat` runs of the scene: the scene's own seed for one run, else run i
/// has seed awcc::derive_seed(scene.seed, i).
std::vector<RunResult> run_repeats(const synth::Scene& scene, const RunOptions& options, int repeat,
                                   const Progress& progress = {});

/// One error over the runs that gave it.
struct ErrorSummary {
  std::string name;     ///< "fscc velocity", ..., "window bias (m/s)"
  std::string key;      ///< its JSON key: "fscc_velocity", ..., "window_bias"
  bool absolute = false;  ///< m/s (window errors); else relative (value / truth - 1)
  Summary95 summary;
};

struct RepeatSummary {
  std::vector<ErrorSummary> errors;
  std::int64_t fscc_undefined = 0, awcc_undefined = 0;  ///< runs without a velocity
  /// Runs of each AWCC quality level (ok, low, insufficient): the AWCC
  /// errors are over the ok and low runs.
  std::int64_t awcc_ok = 0, awcc_low = 0, awcc_insufficient = 0;
};
RepeatSummary summarise_runs(const std::vector<RunResult>& runs);

/// The JSON of several runs: repeat, error (each summary), runs, and the
/// first run's truth, fscc and awcc (docs/output.md).
nlohmann::json repeats_to_json(const std::vector<RunResult>& runs, const RepeatSummary& summary);
/// The table of several runs of the scene whose seed is `seed`, with the
/// runs of each AWCC quality level.
std::string repeats_report(const std::vector<RunResult>& runs, const RepeatSummary& summary, std::uint64_t seed);

}  // namespace study
