#pragma once
// Error against cost, as a lab chooses a method and a record (pdp bench).
// Five fixed scenes (the base case and hard ones), each synthesised with N
// seeds; on each, every method and setting (FSCC; AWCC on the binary signals
// by the interval and FFT paths, and on the raw voltage; the quantile-forest
// correction) over record durations, Np and sampling rates, its processing
// cost (CPU seconds) and its estimates against the truth. Each method is
// processed alone, as pdp process --method fscc or awcc processes a
// recording (awcc::process_binarised; the raw voltage from a file through
// awcc::process_recording), so a row's cost is the method's with the phase
// statistics it comes with. One row per seed and setting.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "correction/model.hpp"
#include "study/tasks.hpp"
#include "synth/scene.hpp"

namespace study {

/// The bench's scenes by name: base, high-tu, small-bubbles, low-c, short-T.
/// Throws std::invalid_argument naming the scene for any other.
synth::Scene bench_scene(const std::string& name);

/// The records and settings of each scene and seed.
struct BenchPlan {
  std::vector<double> durations{10, 30, 60, 150, 300, 600};  ///< the duration series (500 kHz, Np = 10), s
  double base_duration = 60.0;    ///< the Np, fs and raw settings, s
  std::vector<int> nps{5, 15, 20, 30};         ///< besides 10, at the base duration
  std::vector<double> rates{20e3, 100e3, 2e6};  ///< besides 500 kHz, at the base duration, Hz
  bool raw = true;                ///< raw-voltage AWCC at the base duration and rate
};

/// One method and setting on one record.
struct BenchRow {
  std::string scene, method;
  std::uint64_t seed = 0;
  int np = 10;
  double duration = 0, fs = 0;
  double seconds = 0;             ///< CPU seconds of the processing (and the correction)
  std::optional<double> velocity, tu;
  double truth_velocity = 0, truth_tu = 0;
  std::int64_t windows = -1;      ///< AWCC's accepted windows; -1 for FSCC
  std::string status;             ///< ok, or why there is no value
};

/// Every setting of one scene and seed, rows in a fixed order. `model`
/// (optional) adds the corrected AWCC of every interval-path setting; raw
/// recordings are written to `scratch` and removed.
std::vector<BenchRow> bench_one(const std::string& scene, std::uint64_t seed, const BenchPlan& plan,
                                const correction::CorrectionModel* model, const std::filesystem::path& scratch);

/// Every scene with seeds first_seed .. first_seed + seeds - 1 on `threads`
/// threads (the numbers do not depend on them): the rows in scene, seed order.
std::vector<BenchRow> run_bench(const std::vector<std::string>& scenes, int seeds, std::uint64_t first_seed,
                                const BenchPlan& plan, const correction::CorrectionModel* model, int threads,
                                const Progress& progress = {});

/// The bench CSV: its header (with a line break) and one row.
std::string bench_header();
std::string bench_row_text(const BenchRow& row);

}  // namespace study
