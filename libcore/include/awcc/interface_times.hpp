#pragma once
// The interfaces of one tip's bubbles in seconds (METHOD 11): bubble h at a
// tip has a front interface (water -> air, the rising edge) and a rear
// interface (air -> water, the falling edge). Each is timed half way between
// the two samples that straddle the edge: an air interval [start, stop) in
// samples has its front at (start - 1/2) / fs and its rear at (stop - 1/2) / fs,
// so the chord time (rear - front) is exactly (stop - start) / fs and the
// centre is unbiased by the sampling grid. Event detection and the multi-tip
// solvers work on these times, never on sample indices.
//
// A bubble already in contact at the record's first sample, or still in
// contact at its last, has an interface outside the record: its chord is
// censored (shorter than the truth) and it is marked so; callers leave it out
// of per-bubble velocities and sizes rather than report a cut bubble.

#include <vector>

#include "awcc/air_intervals.hpp"

namespace awcc {

/// One bubble's passage at one tip.
struct Crossing {
  double front = 0.0;      ///< water -> air interface, s
  double rear = 0.0;       ///< air -> water interface, s
  bool censored = false;   ///< touches the record's first or last sample: an interface is outside the record
  [[nodiscard]] double chord_time() const { return rear - front; }      ///< s
  [[nodiscard]] double centre() const { return 0.5 * (front + rear); }  ///< s
};

/// The crossings of every air interval of one tip, in time order. An empty
/// record (fs <= 0 or no intervals) gives none.
std::vector<Crossing> crossings(const AirIntervals& tip);

}  // namespace awcc
