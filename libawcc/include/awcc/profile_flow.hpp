#pragma once
// A profile is a flow (METHOD 12): the quantities of the whole cross-section
// from the rows of a profile (positions y from the invert, one recording
// each). Every quantity is defined once here.
//
// Rows are put in increasing y (a note says when they came otherwise); a
// position given twice is refused, as is a profile of fewer than two
// positions. Below, rows 0..n-1 are in increasing y, c_i the void fraction,
// u_i the velocity.
//
//  - Yc, the characteristic depth of level c (Y90 for 0.9): the first
//    crossing of c going up, y_{k-1} + (c - c_{k-1}) (y_k - y_{k-1}) /
//    (c_k - c_{k-1}) with k the first row whose c_k >= c (exactly y_k when
//    c_k = c). None if no row reaches c (not_reached). If the first row
//    already reaches it, the crossing lies below the measured profile: y_0
//    is only an upper bound (below_first_position, flagged), and nothing
//    that needs Y90 is computed from a bound.
//  - C_mean = (1 / span) integral c dy, by the trapezoidal rule through the
//    rows below Y90 and the point (Y90, 0.9), and d = (1 - C_mean) Y90, the
//    equivalent clear-water depth. From the invert to the first position
//    (InvertRule): held, c = c_0 on [0, y_0) (METHOD's decision: the probe's
//    lowest reading is the best guess of the layer it cannot reach); zero,
//    c = 0 there (clear water at the invert); left_out, the integral starts
//    at y_0 and C_mean is the mean over [y_0, Y90]. With held and zero the
//    span is [0, Y90] and d = integral_0^Y90 (1 - c) dy exactly; with
//    left_out d = (1 - C_mean) Y90 takes the layer below y_0 at the mean of
//    the measured span.
//  - Velocity power law u / u90 = (y / Y90)^(1/N): ordinary least squares of
//    ln u_i = ln u90 + (1 / N) ln(y_i / Y90) over the rows with 0 < y_i <=
//    Y90 and a velocity (at least two): slope b = S_xz / S_xx, N = 1 / b
//    (none unless b > 0: u must grow with y), u90 = exp(intercept).
//  - Discharges per unit width, q_w = integral_0^Y90 (1 - c) u dy and q_a =
//    integral_0^Y90 c u dy: the trapezoidal rule of (1 - c_i) u_i and c_i u_i
//    through the rows below Y90 and Y90 itself, where c = 0.9 and u is
//    interpolated linearly between the rows bracketing Y90 (as Y90 is); below
//    the first position u = u90 (y / Y90)^(1/N), so that with c held at c_0
//    integral_0^y0 (1 - c_0) u dy = (1 - c_0) u90 Y90 N / (N + 1)
//    (y_0 / Y90)^((N + 1) / N) (zero: c_0 -> 0; left_out: no layer). Every
//    row up to the one bracketing Y90 needs a velocity. The continuity error
//    (q_w - q) / q against the discharge the lab set, when given.
//  - Air-concentration models with the constraint c(Y90) = 0.9, y' = y / Y90,
//    atanh(sqrt(0.1)) = 0.32745:
//      smooth chute (Chanson 1997): c = 1 - tanh^2(K' - y' / (2 D')),
//        K' = atanh(sqrt(0.1)) + 1 / (2 D'); its depth average is exactly
//        C_mean = 2 D' (tanh K' - sqrt(0.1)) (the integral of sech^2);
//      stepped chute (Chanson & Toombes 2002): c = 1 - tanh^2(K' - y' /
//        (2 D_0) + (y' - 1/3)^3 / (3 D_0)), K' = atanh(sqrt(0.1)) +
//        1 / (2 D_0) - 8 / (81 D_0); published with it the fit C_mean =
//        0.7622 (1.0434 - exp(-3.614 D_0)).
//    D' and D_0 minimise sum (c_i - c(y'_i))^2 over the rows with
//    0 < y_i <= Y90 (at least two; above Y90 is the spray, another regime,
//    and the constraint and C_mean are statements about [0, Y90]): a scan of
//    ln D over [1e-3, 1e2] then golden section within the best bracket (the
//    residual has no floor but rounding, so D is recovered to about 1e-9 of
//    itself from exact points). A minimum at the end of the scan is no fit.
//  - 95 % intervals by Monte Carlo over the rows' own uncertainty: each draw
//    redraws every row independently and recomputes every quantity; the
//    interval is the 2.5 and 97.5 % type-7 quantiles of the draws. A row's
//    value X with interval [lo, hi] is drawn as X + z (X - lo) / 1.96 for a
//    standard normal z < 0 and X + z (hi - X) / 1.96 for z >= 0 (the normal
//    for a symmetric interval; in general the two-piece normal whose median
//    is X and whose 2.5 and 97.5 % quantiles are lo and hi). A velocity given
//    by quantiles (the correction's) is drawn by interpolating the quantiles
//    linearly in normal scores Phi^-1(p), extrapolating the end segments:
//    the same law as the interval when the quantiles are 2.5, 50 and 97.5 %.
//    A corrected velocity's spread is mostly the correction's own
//    uncertainty (the forest's quantiles of the truth given the features),
//    and neighbouring rows of a profile have nearly the same features: their
//    corrections err together, not independently. So the normal score of
//    corrected row i is z_i = a_i z_0 + sqrt(1 - a_i^2) e_i with z_0 one
//    score per draw shared by every corrected row and e_i the row's own, a_i^2
//    = max(0, 1 - (s_i / sigma_i)^2), s_i the half-width / 1.96 of the
//    sampling interval of the velocity it corrects (u_sampling_ci95) and
//    sigma_i = (q(z = 1.96) - q(z = -1.96)) / (2 1.96) of its quantiles: each
//    row keeps its own distribution (z_i is standard normal), its sampling
//    part stays independent and the rest moves with the other rows. Without
//    a sampling interval a_i = 0. Measured (docs/validation.md, "Profile
//    intervals and the correction"): with independent scores the stepped
//    profile's u90 and q_w intervals were a quarter as wide as their errors.
//    A drawn c is clamped to [0, 1] and a drawn u to u >= 0 (a reading
//    cannot leave them). Draw m of seed s uses its own stream (derive_seed(s,
//    m)) over the rows in increasing y: the same seed and rows give the same
//    numbers whatever order the rows came in. A quantity undefined in some
//    draws (a draw whose c never reaches 0.9) has its interval from the
//    defined draws when at most 1 % are undefined (the undefined mass, in
//    one tail at worst, then moves the coverage by at most 1 %, said in the
//    reason), and none above.
//    Measured (profile_flow_test, 200 noisy smooth-chute profiles of 12
//    rows, sd 0.01 in c and 1 % in u, 400 draws): coverage 0.94 to 0.955
//    for Y90, C_mean, d, N, q_w and D', half-widths 0.98 to 1.07 times 1.96
//    sd of the estimates. Where Y90 falls on a row the crossing changes
//    segment there, every quantity through Y90 has a kink, and the same
//    test gave coverage 0.91 to 0.925 and half-widths 0.87 of it: the
//    interval is then somewhat narrow.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "awcc/phase_statistics.hpp"
#include "awcc/validation.hpp"

namespace awcc {

/// Which velocity a row contributes (METHOD 12: the best the row has).
enum class FlowVelocitySource { corrected_awcc, awcc, fscc };
std::string_view to_string(FlowVelocitySource source);  ///< "corrected awcc", "awcc", "fscc"

/// One quantile of a row's velocity distribution.
struct VelocityQuantile {
  double probability = 0.0;  ///< in (0, 1)
  double value = 0.0;        ///< m/s
};

/// One position of a profile.
struct ProfileRow {
  std::string name;           ///< how messages name the row (a file name); "row i" when empty
  double y = 0.0;             ///< distance from the invert, m
  double c = 0.0;             ///< void fraction, -
  Interval95 c_ci95;          ///< must contain c
  double bubble_frequency = 0.0;  ///< F, 1/s (validated and carried; no quantity here uses it)
  Interval95 bubble_frequency_ci95;
  std::optional<double> u;    ///< velocity, m/s; none when the row has none
  FlowVelocitySource u_source = FlowVelocitySource::awcc;
  /// The velocity's distribution for the Monte Carlo: quantiles when given
  /// (at least two, probabilities increasing, values not decreasing), else
  /// the interval. A row with u needs one of them (a velocity without
  /// uncertainty would make every interval too narrow); a zero-width
  /// interval says the velocity is exact.
  std::vector<VelocityQuantile> u_quantiles;
  std::optional<Interval95> u_ci95;
  /// With quantiles (a corrected velocity): the 95 % sampling interval of the
  /// velocity they correct. It is the row's own part of their spread; the
  /// rest is the correction's, shared with the other corrected rows (the
  /// header's Monte Carlo). None: the whole spread is the row's own.
  std::optional<Interval95> u_sampling_ci95;
};

/// From the invert to the first position (the header's C_mean).
enum class InvertRule { held, zero, left_out };
inline constexpr InvertRule invert_rules[] = {InvertRule::held, InvertRule::zero, InvertRule::left_out};
std::string_view to_string(InvertRule rule);  ///< "held", "zero", "left-out"

struct ProfileFlowOptions {
  /// The layer below the lowest position, which no probe reaches. Held: the
  /// lowest reading is the best guess of it (METHOD 12's decision).
  InvertRule invert = InvertRule::held;
  /// Further characteristic depths Yc besides Y90, each c in (0, 1): Y50 and
  /// Y95 are the ones papers report next to Y90.
  std::vector<double> levels{0.5, 0.95};
  /// The discharge per unit width the lab set, m2/s: gives the continuity
  /// error (q_w - q) / q, the check every spillway paper reports. None: no
  /// check.
  std::optional<double> discharge;
  /// Monte Carlo draws of the intervals. 1000 puts the 2.5 % quantile on 25
  /// draws, enough for its sampling error (sd of the quantile's coverage
  /// sqrt(0.025 * 0.975 / 1000) = 0.5 %) to be small beside the 95 %.
  int draws = 1000;
  /// The Monte Carlo seed: the same seed gives the same numbers.
  std::uint64_t seed = 0;
  /// The chute's angle to the horizontal, rad (theta, 0 to pi/2): gives the
  /// residual head H_res = d cos(theta) + q_w^2 / (2 g d^2), the energy a
  /// stilling basin must dissipate. None: no residual head.
  std::optional<double> chute_angle;

  [[nodiscard]] Validation validate() const;
};

/// One quantity of the profile: its value from the rows' values, its 95 %
/// interval by Monte Carlo, and why either is missing or to be read with
/// care (empty when nothing is).
struct FlowQuantity {
  std::optional<double> value;
  std::optional<Interval95> ci95;
  std::string reason;
  int draws_defined = 0;  ///< draws in which the quantity was defined
};

enum class DepthStatus {
  ok,
  not_reached,           ///< no row reaches the level: none
  below_first_position,  ///< the first row already reaches it: y_0 is an upper bound (flagged)
};
std::string_view to_string(DepthStatus status);

struct CharacteristicDepth {
  double level = 0.9;
  DepthStatus status = DepthStatus::not_reached;
  std::optional<double> y;  ///< m: the crossing (ok) or the bound y_0 (below_first_position)
  std::string message;      ///< why not ok
};

/// Yc of `level` for rows at increasing positions `y` with void fractions `c`
/// (the header's rule). Throws std::invalid_argument when the spans differ
/// in size or are empty.
CharacteristicDepth characteristic_depth(std::span<const double> y, std::span<const double> c, double level);

enum class ConcentrationModelKind { smooth_chute, stepped_chute };
std::string_view to_string(ConcentrationModelKind kind);  ///< "smooth chute (Chanson 1997)", ...

/// A fitted air-concentration model, evaluable at any y.
struct ConcentrationModel {
  ConcentrationModelKind kind = ConcentrationModelKind::smooth_chute;
  double diffusivity = 0.0;  ///< D' (smooth) or D_0 (stepped), dimensionless
  double y90 = 0.0;          ///< m
  [[nodiscard]] double k_prime() const;
  /// c at y (m).
  [[nodiscard]] double operator()(double y) const;
};

struct ConcentrationFit {
  FlowQuantity diffusivity;          ///< D' or D_0
  std::optional<double> residual;    ///< rms of c_i - c(y_i) over the fitted rows, -
  std::optional<ConcentrationModel> curve;
  int points = 0;                    ///< rows fitted
};

struct PowerLawFit {
  FlowQuantity n;                    ///< N, -
  FlowQuantity u90;                  ///< m/s
  std::optional<double> residual;    ///< rms of ln u_i - fitted, -
  int points = 0;                    ///< rows fitted
};

struct LevelDepth {
  CharacteristicDepth point;  ///< from the rows' values
  FlowQuantity depth;         ///< value only when point.status is ok
};

enum class ProfileFlowStatus {
  ok,          ///< every quantity has a value (the continuity error only when a discharge was given)
  incomplete,  ///< some have none, each saying why (e.g. no Y90)
  refused,     ///< the profile cannot be used: message says why, nothing computed
};
std::string_view to_string(ProfileFlowStatus status);

struct ProfileFlowResult {
  ProfileFlowStatus status = ProfileFlowStatus::refused;
  std::string message;  ///< why not ok
  [[nodiscard]] bool ok() const { return status == ProfileFlowStatus::ok; }
  ProfileFlowOptions options;
  std::vector<std::string> notes;  ///< what was done to the input (sorted) and how to read it
  /// Those of the notes a user must not miss, for a front end to log (pdp
  /// writes them to stderr): the rows sorted, a row without a velocity. With
  /// warnings() the refusal and the depths flagged below the first position.
  std::vector<std::string> alerts;
  std::vector<ProfileRow> rows;    ///< in increasing y
  std::vector<std::size_t> input_index;  ///< rows[i] was input row input_index[i]

  CharacteristicDepth y90_point;  ///< Y90 from the rows' values, with its status
  FlowQuantity y90;               ///< m; value only when y90_point is ok
  std::vector<LevelDepth> levels;  ///< options.levels, in their order
  FlowQuantity c_mean;             ///< -
  FlowQuantity clear_water_depth;  ///< d, m
  PowerLawFit power_law;
  FlowQuantity water_discharge;    ///< q_w, m2/s
  FlowQuantity air_discharge;      ///< q_a, m2/s
  FlowQuantity continuity_error;   ///< (q_w - q) / q, -
  ConcentrationFit smooth_chute;   ///< D'
  ConcentrationFit stepped_chute;  ///< D_0
  FlowQuantity residual_head;      ///< H_res, m
  int draws = 0;                   ///< Monte Carlo draws made

  /// A few readable lines: every quantity with its interval or its reason,
  /// the rule below the first position, each row's velocity source.
  [[nodiscard]] std::string report() const;
  /// The refusal (message), the alerts, and each depth flagged below the
  /// first position with its reason: what a front end logs as warnings.
  [[nodiscard]] std::vector<std::string> warnings() const;
};

/// The profile quantities, each once: the entry every front end lists them
/// from (the flow JSON's plain quantities, the summary's lines after the
/// fits, Python's Flow table, the report's table). A new quantity of a
/// profile is a FlowQuantity member of ProfileFlowResult, its computation in
/// profile_flow.cpp (the point estimate and each Monte Carlo draw), and one
/// row here.
struct FlowQuantityName {
  std::string_view pointer;     ///< where the flow JSON holds it ("/power_law/n")
  std::string_view symbol;      ///< as papers write it ("q_w")
  std::string_view unit;        ///< SI, as the JSON holds it
  std::string_view meaning;     ///< one line
  std::string_view shown_unit;  ///< the report's unit
  double shown_scale;           ///< from unit to shown_unit
  /// Written by the JSON and the summary from this row alone (the depths,
  /// the power law and the fits carry more and are written by their own code).
  bool plain;
  const FlowQuantity& (*of)(const ProfileFlowResult&);
};
inline constexpr std::array<FlowQuantityName, 11> flow_quantity_names{{
    {"/y90", "Y90", "m", "depth where the void fraction reaches 0.9", "mm", 1e3, false,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.y90; }},
    {"/c_mean", "C_mean", "-", "depth-averaged void fraction", "-", 1.0, true,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.c_mean; }},
    {"/clear_water_depth", "d", "m", "equivalent clear-water depth (1 - C_mean) Y90", "mm", 1e3, true,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.clear_water_depth; }},
    {"/power_law/n", "N", "-", "exponent of the power law u / u90 = (y / Y90)^(1/N)", "-", 1.0, false,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.power_law.n; }},
    {"/power_law/u90", "u90", "m/s", "velocity at Y90 of the power law", "m/s", 1.0, false,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.power_law.u90; }},
    {"/water_discharge", "q_w", "m2/s", "water discharge per unit width", "m\u00b2/s", 1.0, true,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.water_discharge; }},
    {"/air_discharge", "q_a", "m2/s", "air discharge per unit width", "m\u00b2/s", 1.0, true,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.air_discharge; }},
    {"/continuity_error", "continuity_error", "-", "continuity error (q_w - q) / q", "%", 100.0, true,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.continuity_error; }},
    {"/smooth_chute", "D'", "-", "diffusivity, smooth chute (Chanson 1997)", "-", 1.0, false,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.smooth_chute.diffusivity; }},
    {"/stepped_chute", "D_0", "-", "diffusivity, stepped chute (Chanson & Toombes 2002)", "-", 1.0, false,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.stepped_chute.diffusivity; }},
    {"/residual_head", "H_res", "m", "residual head d cos(theta) + q_w^2 / (2 g d^2)", "m", 1.0, true,
     [](const ProfileFlowResult& f) -> const FlowQuantity& { return f.residual_head; }},
}};

/// Why `y` cannot be a profile's positions: a position given twice, naming
/// the two by `names` (one each); empty when none is. profile_flow refuses
/// such rows; a front end may call it before processing, to fail fast.
std::string repeated_position(std::span<const double> y, std::span<const std::string> names);
/// The rule behind it: the first pair (i < j, by j) of positions that are
/// equal, or none. A front end that names its inputs its own way reads it.
std::optional<std::pair<std::size_t, std::size_t>> repeated_position_pair(std::span<const double> y);

/// The profile quantities of `rows` (any order). Throws OptionError when the
/// options are refused; a profile that cannot be used (fewer than two rows,
/// a repeated position, a row out of range) is status refused with the
/// reason, naming the row(s).
ProfileFlowResult profile_flow(std::vector<ProfileRow> rows, const ProfileFlowOptions& options = {});

}  // namespace awcc
