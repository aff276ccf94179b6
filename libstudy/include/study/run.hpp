#pragma once
// One synthetic experiment, end to end and in memory: synthesise a scene,
// process it as pdp process processes a recording (awcc::process_binarised:
// phase statistics per tip, FSCC, AWCC, the tip-order rule), read the
// correction's measurement from the result (correction::measurement_of), and
// score every estimate against the truth. Sweeps, validate, pdp design and
// the bench are loops around process_synthesis; sweeps and validate around
// run_scene.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "awcc/process.hpp"
#include "correction/features.hpp"
#include "synth/scene.hpp"
#include "synth/synthesiser.hpp"

namespace study {

/// What a study runs: the AWCC and FSCC settings of pdp process, and whether
/// to keep the velocity history for window-level errors.
struct RunOptions {
  awcc::AwccOptions awcc;               ///< Np, filter, ROC, weighting, path, refinement
  awcc::FsccOptions fscc;               ///< FSCC settings (max lag 20 ms by default)
  bool run_fscc = true;
  bool run_awcc = true;
  bool window_truth = true;             ///< keep the velocity history for window-level errors
};

/// The processing of a synthesised record: pdp process's with the study's
/// methods and settings, for a probe of separations dx and dy (m). The
/// structure outputs, the velocity spectrum and the sizes per position are
/// not made: a study reads none of them, and they change nothing else.
awcc::ProcessOptions processing_options(const RunOptions& options, double dx, double dy);

/// Synthesises a scene for a study: it needs two tips, the first two being
/// the pair processed (throws std::invalid_argument naming the tips otherwise).
synth::Synthesis synthesise_pair(const synth::Scene& scene, const synth::SynthesisOptions& options = {});

/// awcc::process_binarised of the two signals. Throws std::invalid_argument
/// when the options correlate raw voltages (a synthesised record in memory
/// holds binary signals only: write it with libsynth and process the file).
awcc::ProcessResult process_synthesis(awcc::AirIntervals leading, awcc::AirIntervals trailing,
                                      const awcc::ProcessOptions& options);

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
  double truth_count_rate = 0.0;        ///< particles (bubbles; droplets above c = 0.5) pierced by the leading tip per second, 1/s
  double truth_d32 = 0.0;               ///< E[d^3] / E[d^2] of the bubbles, m
  /// The record processed as pdp process would (tips, fscc, awcc).
  awcc::ProcessResult processed;
  /// What the correction reads of it, by the one builder (correction::measurement_of).
  correction::MeasurementResult measurement;
  // Scores. d32 is pdp process's (the leading tip's Sauter diameter from the
  // velocity ProcessResult::velocity_source chooses, METHOD 4 item 10): it
  // is the d32 of the method whose velocity it used, and none of the other.
  Score fscc_velocity, fscc_turbulence_intensity, fscc_d32;
  Score awcc_velocity, awcc_turbulence_intensity, awcc_d32;
  Score void_fraction, count_rate;      ///< leading tip's phase statistics
  // Window level (AWCC): accepted window velocity minus window-averaged truth.
  std::optional<double> window_bias, window_rms;   ///< m/s
  awcc::Summary accepted_truth, rejected_truth;    ///< true window velocities, m/s
  // A probe of four or more tips, processed bubble by bubble
  // (ProcessResult::probe): the mean vector and Tu per component against the
  // realised flow's, the interfacial area against 6 c / d_b (the scene's
  // expected value, synth::Truth::expected_interfacial_area). No value where
  // the scene has fewer tips or the statistics are not ok.
  std::array<Score, 3> multi_tip_velocity, multi_tip_turbulence_intensity;
  Score multi_tip_interfacial_area;
  double seconds_synth = 0.0;           ///< wall seconds of the synthesis
  double seconds_process = 0.0;         ///< wall seconds of the processing (FSCC and AWCC together, as pdp process)
};

/// Synthesises (synthesise_pair) and processes a scene.
RunResult run_scene(const synth::Scene& scene, const RunOptions& options);

/// JSON of one run: truth, phase, fscc, awcc, error and windows objects (docs/output.md).
nlohmann::json run_to_json(const RunResult& r);

/// The readable table of one run, after each method's status and AWCC's
/// quality level (the lines below).
std::string run_report(const RunResult& r);

/// "FSCC: status ok", or the status and why (a line): what qualifies FSCC's
/// values in pdp validate's and pdp compare's tables.
std::string fscc_status_line(const awcc::FsccResult& f);
/// "AWCC: status ok, quality ok", or the status, the quality level and why,
/// each said once (a line): what qualifies AWCC's values in those tables.
std::string awcc_status_line(const awcc::AwccResult& a);

}  // namespace study
