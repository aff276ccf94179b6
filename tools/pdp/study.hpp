#pragma once
// One synthetic experiment, end to end and in memory: synthesise a scene,
// process it as a lab would (phase statistics, FSCC, AWCC), and score every
// estimate against the truth. pdp validate, compare, sweep and bench are
// loops around this.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "awcc/awcc.hpp"
#include "awcc/fscc.hpp"
#include "awcc/phase_statistics.hpp"
#include "correction/features.hpp"
#include "synth/scene.hpp"

namespace pdp {

struct StudyOptions {
  awcc::AwccOptions awcc;               ///< Np, filter, ROC, weighting, path, refinement
  awcc::FsccOptions fscc;               ///< FSCC settings (max lag 20 ms by default)
  bool run_fscc = true;
  bool run_awcc = true;
  bool window_truth = true;             ///< keep the velocity history for window-level errors
};

/// Value, truth and relative error of one estimate (error = value / truth - 1).
struct Score {
  std::optional<double> value;          ///< empty when the method gave no value
  double truth = 0.0;
  [[nodiscard]] std::optional<double> error() const;
};

struct RunResult {
  synth::Scene scene;
  // The probe geometry processed: trailing tip (second) minus leading tip
  // (first), streamwise, and lateral as the distance across the flow.
  double dx = 0.0, dy = 0.0;            ///< m
  // Truth (realised, of the generated series and bubbles).
  double truth_velocity = 0.0;          ///< realised mean u_x, m/s
  double truth_turbulence_intensity = 0.0;  ///< realised Tu_x
  double truth_void_fraction = 0.0;     ///< leading tip
  double truth_count_rate = 0.0;        ///< bubbles pierced by the leading tip per second, 1/s
  double truth_d32 = 0.0;               ///< E[d^3] / E[d^2] of the bubbles, m
  // Estimates.
  double void_fraction = 0.0, count_rate = 0.0;  ///< leading tip, from its binary signal
  std::optional<awcc::FsccResult> fscc;
  std::optional<awcc::AwccResult> awcc;
  Score fscc_velocity, fscc_turbulence_intensity, fscc_d32;
  Score awcc_velocity, awcc_turbulence_intensity, awcc_d32;
  Score void_fraction_score, count_rate_score;
  // Window level (AWCC): accepted window velocity minus window-averaged truth.
  std::optional<double> window_bias, window_rms;   ///< m/s
  awcc::Summary accepted_truth, rejected_truth;    ///< true window velocities, m/s
  double seconds_synth = 0.0, seconds_process = 0.0, seconds_fscc = 0.0, seconds_awcc = 0.0;
};

RunResult run_scene(const synth::Scene& scene, const StudyOptions& options);

/// What the correction takes from one AWCC result of a synthetic record: its
/// velocity and Tu (when it gave them), the leading tip's c and F, the pair
/// processed, Np, the windows and the record's fs and duration.
correction::Measurement awcc_measurement(const awcc::AwccResult& result, const awcc::PhaseStatistics& lead,
                                         double dx, double dy, int np, double fs, double duration);

/// Mean and 95 % interval (Student t) of a sample of errors.
struct Summary95 {
  std::int64_t count = 0;
  double mean = 0.0, lower = 0.0, upper = 0.0;
};
Summary95 summarise95(const std::vector<double>& values);

/// JSON of one run: truth, fscc, awcc, error and windows objects (docs/output.md).
nlohmann::json run_to_json(const RunResult& r);

/// The readable table of one run.
std::string run_report(const RunResult& r);


}  // namespace pdp
