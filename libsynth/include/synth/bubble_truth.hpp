#pragma once
// The truth per bubble (METHOD 11.7): every bubble that pierces at least one
// tip during the record, with its size and shape, its velocity while it
// interacts with the probe, and at each tip the true interfaces, chord and
// surface normals. Event detection and the multi-tip solvers are validated
// bubble by bubble against it (SynthesisOptions::bubble_truth).
//
// Times are the exact continuous interface times of the synthesiser (the
// roots of the tip-in-ellipsoid quadratic), before any sampling: a sampled
// recording's interface lies within one sample of them.
//
// Velocity. Every bubble follows the fluid velocity series, which changes
// while the bubble passes the probe. The velocity stated is the mean over the
// bubble's interaction interval [interaction_start, interaction_end], from
// its first interface at any tip to its last: (D(end) - D(start)) /
// (end - start), D the common displacement, exact from the piecewise-constant
// series. This is what a multi-tip probe can measure: its solvers take the
// lags between a bubble's interfaces at the tips as one rigid translation,
// so the quantity they estimate is the displacement between those interfaces
// over their time span, not the velocity at any one instant. A bubble whose
// interfaces all fall at one instant (a tangent touch) states the velocity
// at that instant.
//
// Chord. The distance between the front and rear pierce points on the
// bubble's surface: the chord of the ellipsoid along the tip's path
// relative to the bubble (a straight line when the velocity is constant over
// the passage; otherwise the segment joining the ends of the slightly curved
// path, which is what speed x chord time estimates with the bubble's mean
// velocity over the passage).
//
// Normals. The outward unit normal of the bubble's surface at the point the
// tip pierces: at the front interface it points roughly along the bubble's
// motion (the tip meets the bubble's leading face), at the rear against it.
//
// Spray. Above c = 0.5 the particles are droplets (synth::DispersedPhase):
// the table holds one row per pierced droplet with the same columns, its
// front the tip's entry into the droplet (air -> water) and its rear the exit
// (water -> air); the chord is the droplet's.
//
// Memory: one row per pierced bubble, 84 bytes plus 48 bytes a tip.

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "synth/scene.hpp"

namespace synth {

/// One bubble at one tip. A tip the bubble did not pierce during the record
/// has NaN times.
struct TipPierce {
  static constexpr double none = std::numeric_limits<double>::quiet_NaN();
  /// The tip enters the particle (bubble: water -> air; droplet: air ->
  /// water), s; before 0 when the tip was inside as the record began.
  double front = none;
  /// The tip leaves it (bubble: air -> water; droplet: water -> air), s;
  /// NaN when the record ended with the tip inside.
  double rear = none;
  double chord = none;  ///< distance between the front and rear pierce points, m (NaN with rear)
  /// Outward unit normals of the bubble's surface at the front and rear pierce
  /// points, NaN with their time (float: validation compares angles to a
  /// fraction of a degree).
  static constexpr float no_normal = std::numeric_limits<float>::quiet_NaN();
  std::array<float, 3> front_normal{no_normal, no_normal, no_normal};
  std::array<float, 3> rear_normal{no_normal, no_normal, no_normal};

  [[nodiscard]] bool pierced() const { return !std::isnan(front); }
  /// True when the rear interface lies beyond the record's end (front < 0
  /// is a true time and not censored: the pre-roll simulates it).
  [[nodiscard]] bool censored() const { return pierced() && std::isnan(rear); }
};

/// The table, column by column, rows in bubble id order.
struct BubbleTruth {
  std::size_t tip_count = 0;
  std::vector<std::uint64_t> id;            ///< entry order of the bubble among all generated (pre-roll included)
  std::vector<double> diameter;             ///< volume-equivalent diameter, m
  std::vector<Vec3> semi_axes;              ///< along x, y, z, m (d/2 each for a sphere)
  std::vector<Vec3> velocity;               ///< mean over the interaction interval, m/s
  std::vector<double> interaction_start;    ///< first interface at any tip, s
  std::vector<double> interaction_end;      ///< last interface at any tip (within the record), s
  /// Passes beyond the first at any tip (a flow reversal brings the bubble
  /// back over a tip): the tip columns hold the first pass only.
  std::vector<std::int32_t> extra_passes;
  std::vector<TipPierce> pierces;           ///< row-major: row r, tip k at r * tip_count + k

  [[nodiscard]] std::size_t size() const { return id.size(); }
  [[nodiscard]] const TipPierce& pierce(std::size_t row, std::size_t tip) const {
    return pierces[row * tip_count + tip];
  }
  [[nodiscard]] TipPierce& pierce(std::size_t row, std::size_t tip) { return pierces[row * tip_count + tip]; }
};

/// The CSV's columns for a probe of `tip_count` tips, in order: the bubble's
/// own, then for each tip k the same group prefixed "tip<k>_". Written and
/// read by these names only (docs/output.md lists them with units).
std::vector<std::string> bubble_truth_columns(std::size_t tip_count);

/// Writes the table as CSV (atomically). Numbers are written exactly
/// (shortest round-trip text); a NaN is an empty cell. Throws OutputError
/// naming the file.
void write_bubble_truth_csv(const std::filesystem::path& path, const BubbleTruth& table);

/// Reads a table written by write_bubble_truth_csv. Throws InputError naming
/// the file, the line and the column for anything else.
BubbleTruth read_bubble_truth_csv(const std::filesystem::path& path);

}  // namespace synth
