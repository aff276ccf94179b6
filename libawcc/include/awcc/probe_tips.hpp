#pragma once
// A probe's tips: where each is (m) and which recording channel holds it, as
// a user declares them (the options tips, leading-tip and tip-channels; a
// settings file's [probe] table) or as a recording states them
// (RecordingInfo::tip_positions). One declaration of the geometry: the
// dual-tip processing takes its tip pair from it, the multi-tip processing
// (awcc/probe_geometry.hpp) its positions.

#include <array>
#include <string>
#include <vector>

#include "awcc/recording.hpp"
#include "awcc/validation.hpp"

namespace awcc {

struct ProbeTips {
  /// Each tip's position, m (x streamwise, y lateral, z vertical), in the
  /// order declared; empty when none are declared (dx and dy then describe a
  /// tip pair).
  std::vector<std::array<double, 3>> positions;
  int leading = 0;            ///< the leading tip, an index into positions
  /// The recording channel (from 0) of each tip; empty: tip k is channel k.
  std::vector<int> channels;

  [[nodiscard]] bool declared() const { return !positions.empty(); }
  [[nodiscard]] int channel_of(std::size_t tip) const;
  /// Two or more tips, each at its own point, the leading tip among them,
  /// one distinct channel per tip; invalid naming the tip or channel.
  [[nodiscard]] Validation validate() const;
};

/// Tips closer than this are one point: a tip listed twice (m).
inline constexpr double same_point_tolerance = 1e-9;
/// A declared and a recorded separation differing by more than this are
/// two different probes (m): above the rounding of a position written in
/// micrometres, far below any tip spacing.
inline constexpr double separation_tolerance = 1e-6;

/// What is wrong with a list of tip positions (fewer than two tips, a tip
/// listed twice: naming both tips and the point), or empty.
[[nodiscard]] std::string tips_problem(const std::vector<std::array<double, 3>>& positions);
/// What is wrong with a tip-to-channel mapping (a negative or repeated
/// channel, naming the tips), or empty.
[[nodiscard]] std::string channels_problem(const std::vector<int>& channels);

/// The probe of a recording: the declared tips, else the tips the recording
/// states (leading tip and positions by channel), else none (positions
/// empty). Throws InputError naming the file, the tip or channel and the fix:
/// fewer channels than declared tips, a channel mapped beyond the
/// recording's, declared tips whose separations differ from those the file
/// states (both named).
[[nodiscard]] ProbeTips probe_of(const ProbeTips& declared, const RecordingInfo& info);

}  // namespace awcc
