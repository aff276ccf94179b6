#pragma once
// A synthetic profile (issue 31): a cross-section of a chute described by
// laws of the distance y from the invert, one synthetic scene per position,
// and the profile quantities of METHOD 12 it was made from, so that `pdp
// synth --profile` writes a profile to process and `pdp validate --profile`
// compares every profile quantity with its truth.
//
// The cross-section (y' = y / Y90):
//  - void fraction: one of the air-concentration models of
//    awcc/profile_flow.hpp (ConcentrationModel: smooth chute, D'; stepped
//    chute, D_0) up to Y90, where it is 0.9 by construction. Above Y90 the
//    stepped-chute model turns down (its argument is stationary at y' = 1/3
//    + sqrt(1/2) = 1.04, c never exceeds ~0.9003), which no profile does:
//    there c continues as 1 - 0.1 exp(-(y - Y90) s / 0.1), s = dc/dy at Y90
//    from below (a central difference of the model), the C1 continuation that
//    rises to 1. The same rule is used for both models, so that the spray
//    region is one law whatever the model; every quantity of the truth is a
//    statement about [0, Y90] and does not depend on it.
//  - velocity: the power law u = u90 (y / Y90)^(1/N) at every y.
//  - turbulence intensity Tu_x: linear in y' from tu_invert (y = 0) to tu_y90
//    (y = Y90), held beyond; Tu_y and Tu_z keep the scene's ratios to Tu_x.
//  - bubble (or droplet) diameter d_b: linear in y' from the invert's to
//    Y90's, held beyond; the scene's diameter_log_sd is their spread.
// Every other scene field (fs, duration, probe, time scales, arrival rule,
// shape) is the profile's base scene's, and position i has the seed
// derive_seed(scene.seed, i).
//
// Truth (ProfileTruth), from the laws, never from the positions:
//   Yc: the model's crossing of c (bisection on [0, y_max]; the law rises
//       monotonically: the stepped model's argument falls on [0, 1.04 Y90]);
//       none where c(0) already exceeds c.
//   C_mean = (1 / Y90) int_0^Y90 c dy, d = (1 - C_mean) Y90 = int_0^Y90 (1 - c) dy,
//   q_w = int_0^Y90 (1 - c) u dy, q_a = int_0^Y90 c u dy,
// by composite Simpson's rule, in s = (y / Y90)^(1/N) for the discharges (y
// = Y90 s^N, dy = N Y90 s^(N-1) ds: the integrand is then smooth at the
// invert, where u ~ y^(1/N) has an infinite slope). 4,096 panels: the rule's
// error is below 1e-9 relative (tests compare the smooth model's closed form
// C_mean = 2 D' (tanh K' - sqrt(0.1))).
//   N, u90 and the model's D: as imposed (the other model's D has no truth).
//
// Note: under equal-time arrivals (synth::ArrivalRule::equal_time) a tip sees
// the dispersed phase's fraction times (1 + Tu_x^2) (METHOD 5.2), so the
// profile's measured c is not the law's; the samples use equal-space arrivals,
// whose tip sees the law's c.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "awcc/option_field.hpp"
#include "awcc/profile_flow.hpp"
#include "awcc/validation.hpp"
#include "correction/model.hpp"
#include "study/run.hpp"
#include "synth/scene.hpp"

namespace study {

struct ProfileSpec {
  /// The air-concentration law below Y90.
  awcc::ConcentrationModelKind model = awcc::ConcentrationModelKind::stepped_chute;
  /// D_0 (stepped) or D' (smooth), -. 0.2: a stepped chute's C_mean of 0.41.
  double diffusivity = 0.2;
  double y90 = 0.05;                     ///< Y90, m
  double u90 = 5.0;                      ///< velocity at Y90, m/s
  double power_law_n = 6.0;              ///< N of u = u90 (y / Y90)^(1/N), -
  double tu_invert = 0.2;                ///< Tu_x at the invert, -
  double tu_y90 = 0.1;                   ///< Tu_x at Y90 and above, -
  double bubble_diameter_invert = 3e-3;  ///< d_b at the invert, m
  double bubble_diameter_y90 = 2e-3;     ///< d_b at Y90 and above, m
  std::vector<double> positions;         ///< y of each recording, m: increasing, > 0
  /// Every other field of each position's scene (its void fraction,
  /// velocity, Tu_x and d_b are the laws'; its Tu_y / Tu_x and Tu_z / Tu_x
  /// ratios are kept).
  synth::Scene scene;

  /// ok, or each problem naming its field: a law out of its range, positions
  /// not increasing or not positive, a position whose scene is refused
  /// (e.g. c below the synthetic probe's range near the invert).
  [[nodiscard]] awcc::Validation validate() const;
};

/// The settings of a profile file's [profile] table: each field's name (a
/// settings key and `pdp synth` / `pdp validate` see them in help), unit,
/// help, parser and formatter.
std::span<const awcc::OptionField<ProfileSpec>> profile_spec_fields();

/// Reads a profile file: its [profile] table (profile_spec_fields()) and an
/// optional [scene] table (synth::scene_fields(); void-fraction, velocity, tu
/// and bubble-diameter are the laws' and refused there). Throws InputError
/// naming the file, the line, the key and the fix. Not validated.
ProfileSpec load_profile_spec(const std::filesystem::path& path);

/// The void fraction of the cross-section at y (m), -.
double profile_void_fraction(const ProfileSpec& spec, double y);
/// The velocity at y, m/s (0 at the invert).
double profile_velocity(const ProfileSpec& spec, double y);
/// The scene of position i (the laws at positions[i], seed derived).
synth::Scene position_scene(const ProfileSpec& spec, std::size_t i);

struct ProfileTruth {
  double y90 = 0.0;                     ///< m
  std::vector<double> levels;           ///< the levels of `depths`
  std::vector<std::optional<double>> depths;  ///< Yc of each level, m; none below the invert
  double c_mean = 0.0;                  ///< -
  double clear_water_depth = 0.0;       ///< d, m
  double power_law_n = 0.0, u90 = 0.0;  ///< -, m/s
  double water_discharge = 0.0;         ///< q_w, m2/s
  double air_discharge = 0.0;           ///< q_a, m2/s
  awcc::ConcentrationModelKind model{};
  double diffusivity = 0.0;             ///< the model's D
};

/// The truth of `spec` with the characteristic depths of `levels`.
ProfileTruth profile_truth(const ProfileSpec& spec, std::span<const double> levels);

/// JSON of the spec and its truth (the profile truth file `pdp synth
/// --profile` writes; docs/output.md).
nlohmann::json profile_truth_json(const ProfileSpec& spec, const ProfileTruth& truth);

struct ProfileValidateOptions {
  RunOptions run;                   ///< how each position is processed (pdp process's)
  /// The profile quantities' options. Its discharge is set to the truth's
  /// q_w, so that the continuity error is the water discharge's error.
  awcc::ProfileFlowOptions flow;
  /// The bias correction applied to every position (pdp process --correct):
  /// a corrected row contributes its corrected AWCC median (METHOD 12's best
  /// velocity). None: AWCC's or FSCC's velocity, uncorrected.
  const correction::CorrectionModel* correction = nullptr;
};

/// One profile quantity against its truth.
struct ProfileComparison {
  std::string name;                  ///< "Y90", "C_mean", ...
  std::string key;                   ///< JSON key: "y90", "c_mean", ...
  std::string unit;                  ///< "m", "-", "m/s", "m2/s"
  double truth = 0.0;
  /// From exact rows: the laws' c and u at the positions without error, so
  /// that value - exact_rows is the measurement's part of the error and
  /// exact_rows - truth the positions' (trapezoidal rule, the layer below
  /// the first position).
  std::optional<double> exact_rows;
  awcc::FlowQuantity measured;       ///< from the processed rows, with its 95 % interval
  [[nodiscard]] std::optional<double> error() const;  ///< measured / truth - 1
  [[nodiscard]] std::optional<bool> covered() const;  ///< truth within the 95 % interval
};

struct ProfileValidation {
  ProfileSpec spec;
  ProfileTruth truth;
  std::vector<RunResult> runs;          ///< one per position, in the spec's order
  std::vector<correction::Correction> corrections;  ///< one per position when a model was given
  awcc::ProfileFlowResult flow;         ///< from the processed rows (correction::profile_row)
  awcc::ProfileFlowResult exact_flow;   ///< from exact rows
  std::vector<ProfileComparison> comparisons;
  double seconds = 0.0;                 ///< wall time

  /// The comparison table and a row per position (readable).
  [[nodiscard]] std::string report() const;
};

/// Synthesises and processes every position (run_scene), builds the rows as
/// pdp process does (correction::profile_row) and compares the profile
/// quantities with the truth. Throws OptionError for a spec refused by
/// validate(). `progress` gets the fraction of positions done.
ProfileValidation validate_profile(const ProfileSpec& spec, const ProfileValidateOptions& options,
                                   const std::function<void(double)>& progress = {});

/// JSON of a validation (docs/output.md): the truth, the comparisons, the
/// positions and the flow object of the processed rows.
nlohmann::json profile_validation_json(const ProfileValidation& v);

}  // namespace study
