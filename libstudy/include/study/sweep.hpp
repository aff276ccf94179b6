#pragma once
// Studies over many synthetic scenes: a sweep definition (TOML), its
// expansion into runs, and the run rows of the append-only CSV (each run
// processed by run_scene, as pdp process processes a recording).
//
// Definition:
//   [sweep]  mode = "grid" | "monte-carlo", runs (monte-carlo), repeat, seed
//   [base]   fixed scene fields (synth::scene_fields' names, numbers in SI or
//            strings with units), plus np and anisotropy (Tu_y/Tu_x = Tu_z/Tu_x,
//            applied when tu-y/tu-z are not set; default 0.5)
//   [grid]   a list of values per field: the runs are their Cartesian product
//   [ranges] [min, max] per field: Monte Carlo draws uniformly, the integral
//            time scale log-normally (mean and sd of ln T from the range ends,
//            ln T = mid +/- 2 sd, truncated). Monte Carlo defaults are METHOD 5's
//            ranges: velocity 1-50 m/s, tu 0-0.35, time-scale 1 ms-1 s,
//            void-fraction 0.005-0.4, bubble-diameter 0.5-20 mm, dx 0.5-10 mm.
//   [choices] a list of values per field (monte-carlo): each run takes one,
//            each equally likely, e.g. arrival = ["equal-time", "poisson-space"]
//            to mix the simulators' conventions in one campaign. A field is
//            set in one table only.
// Run i (of `repeat` per parameter set) has seed awcc::derive_seed(seed, i):
// results do not depend on thread count, order or sharding.

#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "study/run.hpp"

namespace study {

struct SweepRun {
  std::int64_t index = 0;
  synth::Scene scene;
  int np = 10;
  double anisotropy = 0.5;
};

struct SweepDefinition {
  std::string mode = "grid";
  std::int64_t runs = 0;        ///< monte-carlo parameter sets
  std::int64_t repeat = 1;
  std::uint64_t seed = 1;
  std::string canonical;        ///< a canonical text of the definition, for the study id
  std::vector<SweepRun> expand() const;
  std::map<std::string, std::string> base, grid_text;
  std::map<std::string, std::vector<std::string>> grid;
  std::map<std::string, std::pair<double, double>> ranges;  ///< SI
  /// Ranges drawn log-uniformly ([min, max, "log"]); the others uniformly
  /// (time-scale: log-normal, see expand).
  std::set<std::string> log_ranges;
  /// [choices]: the values one of which each monte-carlo run takes, equally likely.
  std::map<std::string, std::vector<std::string>> choices;
};

/// Reads and checks a sweep file; throws awcc::OptionError (a definition
/// that cannot be run) naming the file, the table and key, and the fix.
SweepDefinition load_sweep(const std::filesystem::path& path);

/// True when the definition sets `name` (in [base], [grid], [ranges] or [choices]).
[[nodiscard]] bool sets(const SweepDefinition& d, const std::string& name);

/// The CSV header and one row, in the columns correction/sweep_columns.hpp
/// declares (training reads them by those names): the scene, np and anisotropy, the truth, the
/// estimates, the probe geometry processed (probe_dx, probe_dy), run times,
/// the reason a run failed, and the AWCC processing (awcc_filter_a ...).
/// What the correction reads (awcc_velocity, awcc_turbulence_intensity,
/// awcc_void_fraction, awcc_count_rate, the windows, fscc_velocity, probe_dx,
/// probe_dy) is the run's measurement (RunResult::measurement): empty where
/// it has none, with the reason. `result` is null for a run that failed
/// (`error` says why).
std::string sweep_header();
std::string sweep_row(const SweepRun& run, const RunResult* result, const std::string& error, std::uint64_t study,
                      const awcc::AwccOptions& processing);

/// Runs one sweep run (its np applied to `options`) and returns its CSV
/// row with a line break: a run that throws is a row with the reason.
std::string run_sweep_row(const SweepRun& run, const RunOptions& options, std::uint64_t study);

/// Study id of a definition (FNV-1a of its canonical text).
std::uint64_t study_id(const SweepDefinition& d);

/// Runs already in an existing CSV of this study. A partial last line (a
/// crash while writing) is cut off. Throws awcc::InputError when the file is
/// not such a CSV (foreign header, malformed row, rows of another study).
std::set<std::int64_t> finished_runs(const std::filesystem::path& csv, std::uint64_t study);

}  // namespace study
