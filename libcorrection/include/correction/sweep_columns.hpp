#pragma once
// The sweep CSV's columns, declared once: pdp sweep (libstudy) writes its
// rows in this order, training reads them by these names, and a resumed sweep
// checks the header against them. The order is the file format: sweeps
// written earlier resume, so a column is only ever added at the end.
//
// A row is: the key columns, then the scene's fields (synth::scene_fields'
// names with '-' written '_', without seed; numbers in SI), then the result
// columns. The scene's fields are declared by the scene (libsynth); the
// correction reads four of them (sweep_scene_columns).

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/awcc.hpp"
#include "awcc/fscc.hpp"

namespace correction {

struct SweepColumnInfo {
  std::string_view name;
  std::string_view unit;  ///< "-" for numbers without one, "text" for words
  std::string_view meaning;
};

/// The first columns of every row: what identifies a run.
inline constexpr std::array<SweepColumnInfo, 3> sweep_key_columns{{
    {"study", "-", "the study's id (of its sweep definition): rows of another study are refused"},
    {"run", "-", "the run's index in the study"},
    {"seed", "-", "the run's scene seed"},
}};

/// The scene's columns the correction reads (declared by synth::scene_fields).
struct SweepSceneColumns {
  static constexpr std::string_view dx = "dx", dy = "dy", fs = "fs", duration = "duration";
  /// The imposed mean velocity and Tu_x (TruthKind::imposed).
  static constexpr std::string_view velocity = "velocity", tu = "tu";
};

/// The columns after the scene's, in the order written.
enum class SweepColumn : std::size_t {
  np, anisotropy,
  truth_velocity, truth_turbulence_intensity, truth_void_fraction, truth_count_rate, truth_d32,
  awcc_velocity, awcc_turbulence_intensity, awcc_void_fraction, awcc_count_rate, awcc_d32,
  awcc_windows_accepted, awcc_windows_total,
  awcc_velocity_error, awcc_turbulence_intensity_error, awcc_d32_error,
  fscc_velocity, fscc_turbulence_intensity_chanson, fscc_r12_max, fscc_velocity_error,
  window_bias, window_rms,
  seconds_synth, seconds_process, seconds_fscc, seconds_awcc,
  reason,
  probe_dx, probe_dy,
  awcc_filter_a, awcc_roc, awcc_weighting, awcc_signal, awcc_subsample,
  truth_velocity_y, truth_velocity_z, truth_turbulence_intensity_y, truth_turbulence_intensity_z,
  truth_interfacial_area,
  multi_tip_velocity_x, multi_tip_velocity_y, multi_tip_velocity_z,
  multi_tip_turbulence_intensity_x, multi_tip_turbulence_intensity_y, multi_tip_turbulence_intensity_z,
  multi_tip_interfacial_area, multi_tip_quality, multi_tip_bubbles_accepted,
  awcc_velocity_unweighted, awcc_turbulence_intensity_unweighted,
  generator_version,
  awcc_time_scale_ratio,
  awcc_weighting_gap, awcc_weighting_gap_ci95_lower, awcc_weighting_gap_ci95_upper,
  count
};

inline constexpr std::size_t sweep_result_column_count = static_cast<std::size_t>(SweepColumn::count);

inline constexpr std::array<SweepColumnInfo, sweep_result_column_count> sweep_result_columns{{
    {"np", "-", "points per AWCC window"},
    {"anisotropy", "-", "Tu_y/Tu_x = Tu_z/Tu_x of the scene"},
    {"truth_velocity", "m/s", "the scene's realised mean streamwise velocity"},
    {"truth_turbulence_intensity", "-", "the scene's realised streamwise turbulence intensity"},
    {"truth_void_fraction", "-", "the scene's realised void fraction"},
    {"truth_count_rate", "1/s", "the scene's realised bubble count rate"},
    {"truth_d32", "m", "the scene's realised Sauter mean diameter"},
    {"awcc_velocity", "m/s", "the measurement's AWCC velocity (what the correction reads)"},
    {"awcc_turbulence_intensity", "-", "the measurement's AWCC turbulence intensity"},
    {"awcc_void_fraction", "-", "the measurement's void fraction"},
    {"awcc_count_rate", "1/s", "the measurement's bubble count rate"},
    {"awcc_d32", "m", "the Sauter mean diameter from AWCC's velocity"},
    {"awcc_windows_accepted", "-", "AWCC windows accepted"},
    {"awcc_windows_total", "-", "AWCC windows in the record"},
    {"awcc_velocity_error", "-", "AWCC velocity / truth - 1, of what pdp process reports"},
    {"awcc_turbulence_intensity_error", "-", "AWCC Tu / truth - 1"},
    {"awcc_d32_error", "-", "AWCC d32 / truth - 1"},
    {"fscc_velocity", "m/s", "the FSCC velocity"},
    {"fscc_turbulence_intensity_chanson", "-", "FSCC's turbulence intensity (Chanson)"},
    {"fscc_r12_max", "-", "the peak of FSCC's cross-correlation"},
    {"fscc_velocity_error", "-", "FSCC velocity / truth - 1"},
    {"window_bias", "-", "mean of the window velocities' relative errors"},
    {"window_rms", "-", "RMS of the window velocities' relative errors"},
    {"seconds_synth", "s", "time to synthesise the scene"},
    {"seconds_process", "s", "time to process the record (FSCC and AWCC together)"},
    {"seconds_fscc", "s", "empty: FSCC runs with AWCC"},
    {"seconds_awcc", "s", "empty: AWCC runs with FSCC"},
    {"reason", "text", "why the run failed, or why AWCC gave no value or was probe-corrected"},
    {"probe_dx", "m", "the streamwise separation processed (written for failed runs too)"},
    {"probe_dy", "m", "the lateral separation processed"},
    {"awcc_filter_a", "-", "AWCC's filter A"},
    {"awcc_roc", "text", "AWCC's robust outlier cutoff: on or off"},
    {"awcc_weighting", "text", "AWCC's window weighting (awcc::to_string(Weighting))"},
    {"awcc_signal", "text", "the signals correlated (awcc::to_string(CorrelationSignal))"},
    {"awcc_subsample", "text", "the peak refinement (awcc::to_string(Subsample))"},
    {"truth_velocity_y", "m/s", "the scene's realised mean lateral velocity"},
    {"truth_velocity_z", "m/s", "the scene's realised mean vertical velocity"},
    {"truth_turbulence_intensity_y", "-", "the scene's realised Tu_y (rms v_y / |mean vector|)"},
    {"truth_turbulence_intensity_z", "-", "the scene's realised Tu_z"},
    {"truth_interfacial_area", "1/m", "the scene's expected interfacial area concentration, 6 c / d_b"},
    {"multi_tip_velocity_x", "m/s", "a probe of four or more tips: the mean vector's x component (empty otherwise)"},
    {"multi_tip_velocity_y", "m/s", "the mean vector's y component"},
    {"multi_tip_velocity_z", "m/s", "the mean vector's z component"},
    {"multi_tip_turbulence_intensity_x", "-", "multi-tip Tu_x"},
    {"multi_tip_turbulence_intensity_y", "-", "multi-tip Tu_y"},
    {"multi_tip_turbulence_intensity_z", "-", "multi-tip Tu_z"},
    {"multi_tip_interfacial_area", "1/m", "multi-tip interfacial area concentration"},
    {"multi_tip_quality", "text", "multi-tip quality: ok, low or insufficient"},
    {"multi_tip_bubbles_accepted", "-", "bubbles with an accepted velocity vector"},
    {"awcc_velocity_unweighted", "m/s",
     "AWCC's mean velocity of the same accepted windows with unweighted moments, when the run was processed with "
     "duration weighting (empty otherwise): the other tools' convention, at no cost (issue 33)"},
    {"awcc_turbulence_intensity_unweighted", "-", "AWCC's Tu of the same accepted windows, unweighted"},
    {"generator_version", "-",
     "the version of the seeded streams that made the run (awcc::generator_version; sweeps written before the "
     "column existed are version 1)"},
    {"awcc_time_scale_ratio", "-",
     "T_u / T_W of AWCC's accepted windows, capped at 20 (correction::Features::time_scale_ratio; the feature of the "
     "+scale sets)"},
    {"awcc_weighting_gap", "-",
     "AWCC's weighting gap g = u_unweighted / u_weighted - 1 of the accepted windows (awcc/weighting_gap.hpp: near 0 "
     "for bubbles arriving in time); not a feature of the correction (METHOD 7 (d))"},
    {"awcc_weighting_gap_ci95_lower", "-", "its 95 % interval (block jackknife), lower end"},
    {"awcc_weighting_gap_ci95_upper", "-", "its 95 % interval, upper end"},
}};

[[nodiscard]] constexpr std::string_view column_name(SweepColumn c) {
  return sweep_result_columns[static_cast<std::size_t>(c)].name;
}

/// The first column written for a failed run too (the probe and the processing).
inline constexpr SweepColumn sweep_first_trailing_column = SweepColumn::probe_dx;

/// The whole header, given the scene's column names (in the scene's order).
std::string sweep_csv_header(const std::vector<std::string>& scene_columns);

/// The processing's enum columns as written: "on"/"off" and awcc::to_string.
std::string_view roc_text(bool roc);
/// Reads one enum cell; std::nullopt when the text names no value (the
/// caller refuses it naming the file, the row and the value).
std::optional<bool> roc_of(std::string_view text);
std::optional<awcc::Weighting> weighting_of(std::string_view text);
std::optional<awcc::CorrelationSignal> signal_of(std::string_view text);
std::optional<awcc::Subsample> subsample_of(std::string_view text);

}  // namespace correction
