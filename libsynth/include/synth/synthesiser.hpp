#pragma once
// The synthetic probe: bubbles carried by the fluid past point tips
// (METHOD.md 5.2-5.4), with each tip's air intervals found exactly.
//
// Spray. Above c = 0.5 the particles are water droplets in air
// (synth::DispersedPhase): everything below holds for them with the
// dispersed fraction c_d = 1 - c in place of c, and a tip's air intervals
// are the complement of its pierces over [0, N samples). "Bubble" below
// means the particle of either phase.
//
// Geometry. The probe's centre is the middle of the tips' bounding box. The
// control volume has edges L_i = spread_i + 4 a_max,i (spread_i the tips'
// extent along i, a_max,i the largest bubble semi-axis along i: 2 d_b for
// spheres). Bubbles enter at x = -L_x/2 at a uniform (y, z) of the cross
// section A = L_y L_z, at the rate F_cv = c_d |u| A / E[V_b] (c_d = c for
// bubbles), so that a tip sees the dispersed fraction c_d. No slip: every bubble moves with the fluid, so all
// bubbles share one displacement D(t) and bubble k sits at
//
//   x_k(t) = E_k + D(t) - D(t_k),     t >= t_k (its entry time).
//
// The cross-section is periodic (y and z taken modulo L_y, L_z): the common
// transverse drift during the transit (sigma_y x L_x / u, about 1 mm in the
// base case) would otherwise empty a strip along one wall of the control
// volume and the downstream tip would see up to ~5 % less air than c. With
// the periodic tile the lateral bubble field stays homogeneous whatever the
// drift. Overlap avoidance uses the same minimum-image rule.
//
// Dense placement. Bubbles never overlap when it can be helped: a bubble
// whose lateral positions tried (overlap_retries + 1) all overlap waits and
// tries again as the flow advances, and after one largest diameter of flow
// it is placed overlapping (Truth::overlaps_unresolved). Random sequential
// placement jams near a dispersed fraction of 0.38-0.42, so above it a third
// of the particles at c_d = 0.5 overlap, and the volume they share is lost:
// the realised c fell to 0.468 at c = 0.5 and droplets at 0.5 + 1e-9 gave
// 0.532, a jump at the switch of phases. Under the space arrival rules the
// particle is instead placed at the position tried that shares the least
// volume with its neighbours, and that volume (the sum of the pairwise
// sphere-sphere lenses in the sphere-mapped space, which keeps volumes:
// synth/overlap.hpp) brings the next mark forward by lost / (c_d A), so the
// dispersed volume per unit of flow is c_d A as the rate asks. A point
// inside two neighbours is counted twice, but two neighbours share volume
// only when one of them was itself placed overlapping; measured, the excess
// is a negligible part of what is compensated (docs/validation.md). The
// least-sharing position keeps the compensation small (0.19 % of the flow at
// c = 0.5 against 6.8 % placing at the last position tried), so few extra
// particles are placed and the tips' pierce count exceeds 1.5 c_d |u| / d by
// that little: the truth is then 1.5 (c_d + f) |u| / d with f =
// Truth::compensated_volume_fraction. A mark never moves behind the current
// displacement: what is owed beyond it moves the marks after it. The time
// rules compensate nothing: there a particle's volume per unit of flow is
// c_d U / u(t), above 1 while the flow is slow, particles pile up on each
// other and the pairwise sum counts the same volume many times; bringing
// arrivals forward then feeds the pile (measured: compensated, the base case
// and samples/high-tu.toml ran for minutes where they take a fraction of a
// second).
// A scene without an unresolved overlap, and every scene under the time
// rules, gives the output it gave before. Deterministic: the positions tried
// are the draws made anyway, and the marks move at events, whatever the
// chunk size.
//
// Piercing. The velocity is constant over each realisation step, so D(t) is
// piecewise linear and, over one step, the tip-relative position of a bubble is
// q + v s. Tip j is inside an ellipsoid with semi-axes a when
// |(q + v s) / a|^2 < 1: a quadratic in s whose roots are the exact entry and
// exit times. Sample n is air when the tip is inside at t = n / fs, i.e. for
// n in (t_in fs, t_out fs). A bubble is tested at the steps whose
// streamwise range can bring it within reach of a tip, when it leaves the
// control volume (or the record ends), walking the velocity steps kept since
// it entered: as all bubbles share one displacement, the steps that reach a
// bubble of key D_x(t_k) follow from that key, and from the last bubble's;
// a bubble further from a tip laterally than its semi-axis and the lateral
// path of its passage is passed over at once.
//
// Memory does not grow with duration: velocities are generated a chunk at a
// time and bubbles are retired once well downstream (R_back = max(2 L_x,
// 4 sigma_x T_x) past the last tip, so that a reversal of the flow can bring
// them back only if it exceeds that; Truth::reentries_missed counts steps where
// it could have); the steps are kept from the earliest entry of a bubble
// still in the volume (80 bytes a step and 16 a step and tip: about 2 MB in
// the base case, whose bubbles stay about 2,000 steps). The air intervals
// (16 bytes per chord) and, on request, the velocity history are the only
// outputs that grow, and on request the truth per bubble
// (synth/bubble_truth.hpp), one row per pierced bubble.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "awcc/air_intervals.hpp"
#include "awcc/option_field.hpp"
#include "synth/bubble_truth.hpp"
#include "synth/scene.hpp"
#include "synth/truth.hpp"

namespace synth {

struct SynthesisOptions {
  std::int64_t chunk_steps = 1 << 16;   ///< velocity steps generated at a time (results do not depend on it)
  bool keep_velocity_history = false;   ///< keep the streamwise history for window-averaged truth (8 bytes a step)
  bool keep_reference_data = false;     ///< keep every bubble and step velocity for brute-force checks (tests only)
  /// The truth per pierced bubble (Synthesis::bubbles) and the interfacial
  /// area concentration at each tip (TipTruth::interfacial_area). Off, it
  /// costs nothing; on, 84 bytes plus 48 a tip per pierced bubble (0.26 us
  /// and 180 bytes a bubble for the two-tip base case).
  bool bubble_truth = false;
  std::function<void(double)> progress; ///< called with the fraction done, once per chunk
};

/// A bubble as generated: what a brute-force reference needs to place it.
struct BubbleRecord {
  double t_entry = 0.0;   ///< s
  Vec3 entry;             ///< entry point relative to the probe centre, m
  Vec3 key;               ///< common displacement D(t_entry), m
  Vec3 semi_axes;         ///< m
};

/// Inputs of the brute-force reference (keep_reference_data).
struct ReferenceData {
  double t_start = 0.0;              ///< time of step 0 (negative: pre-roll fills the control volume), s
  double step = 0.0;                 ///< s
  std::vector<Vec3> velocities;      ///< velocity of every step from t_start
  std::vector<BubbleRecord> bubbles; ///< in entry order
  std::vector<Vec3> tips;            ///< tip positions relative to the probe centre, m
  Vec3 control_volume;               ///< edges L_x, L_y, L_z (lateral edges are periodic), m
};

struct Synthesis {
  std::vector<awcc::AirIntervals> signals;   ///< one per tip, in tip order
  Truth truth;
  std::optional<VelocityHistory> history;    ///< with keep_velocity_history
  std::optional<ReferenceData> reference;    ///< with keep_reference_data
  std::optional<BubbleTruth> bubbles;        ///< with bubble_truth
};

/// The synthesis options a user sets (settings key and pdp synth flag
/// bubble-truth); the others are for tests and front ends' progress.
std::span<const awcc::OptionField<SynthesisOptions>> synthesis_option_fields();

/// Synthesises a valid scene (throws invalid_scene(scene.validate())
/// otherwise).
Synthesis synthesise(const Scene& scene, const SynthesisOptions& options = {});

/// Reference piercing by testing every sample of every tip against every
/// candidate particle (the dense method the exact one replaces): returns one
/// 0/1 vector per tip, 1 = air (inside a bubble; outside every droplet in the
/// spray region). For tests and the benchmark.
std::vector<std::vector<std::uint8_t>> brute_force_signals(const Scene& scene, const ReferenceData& reference);

/// Same, but as a form whose sign margin says how close the sample is to a
/// surface: for every tip and sample, f = min over particles of
/// |(x_tip - x_k)/a|^2 for bubbles, 2 - that for droplets; so in either phase
/// f < 1 is air, f > 1 water and f = 1 a surface. Lets a test tell a genuine
/// disagreement from a sample that sits on a surface to rounding.
std::vector<std::vector<double>> brute_force_distances(const Scene& scene, const ReferenceData& reference);

}  // namespace synth
