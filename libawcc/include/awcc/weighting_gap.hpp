#pragma once
// The weighting gap of an AWCC result (METHOD 7 (d)): which arrival rule the
// bubbles follow, read from the accepted windows.
//
//   g = u_unweighted / u_weighted - 1,
//
// u_weighted the duration-weighted mean of the windows' velocities (sum T_W u
// / sum T_W), u_unweighted their plain mean, over the same accepted windows.
// When bubbles arrive spaced along the flow, a window of Np bubbles lasts
// longer when the flow is slow, the weights anti-correlate with u and g is
// about the windows' relative velocity variance (measured on the conventions
// campaign: g / Tu^2 at a median of 0.9 where T_u / T_W > 1, 0.5 below).
// When arrivals are set in time (the paper's rule, pdp's default and the
// correction's training prior), a window's duration does not depend on the
// velocity and g is near 0 (g / Tu^2 at a median of 0.05-0.17, its 90th
// percentile 0.26-0.43). g is not a feature of the correction (a peer's file
// never has it): it says whether the correction's prior holds.
//
// Sampling interval (95 %): a delete-a-block jackknife over B = 10 blocks of
// consecutive accepted windows (blocks, so that windows correlated through
// the velocity's integral time scale fall mostly in one block), with
// Student's t of B - 1 = 9 degrees of freedom (2.262): g_b is g without
// block b, se^2 = (B - 1) / B sum (g_b - mean g_b)^2, interval g +/- 2.262 se.
// With fewer than 2 B windows a block is one or two windows.
//
// The flag: arrivals along the flow are indicated when the interval's lower
// end exceeds the allowance kappa Tu^2, kappa = time_arrival_gap_allowance
// (0.5: above the 90th percentile of g / Tu^2 that arrivals in time gave in
// every band of accepted windows, and at or below the median that arrivals
// along the flow gave where the window is shorter than the time scale).
#include <cstddef>
#include <span>

#include "awcc/phase_statistics.hpp"

namespace awcc {

/// kappa of the rule above, -.
inline constexpr double time_arrival_gap_allowance = 0.5;
/// Blocks of the jackknife.
inline constexpr int weighting_gap_blocks = 10;

struct WeightingGap {
  double value = 0.0;         ///< g, -
  Interval95 ci95;            ///< block jackknife (see above), -
  double allowance = 0.0;     ///< kappa Tu^2, -: what arrivals in time allow
  /// The interval lies above the allowance: the bubbles look spaced along
  /// the flow, and the correction's prior (arrivals in time) does not hold.
  bool along_flow = false;
};

/// The gap of the accepted windows' velocities (m/s) and durations (s), in
/// time order, for a result of turbulence intensity `tu`. At least 2 windows.
WeightingGap weighting_gap(std::span<const double> velocities, std::span<const double> durations, double tu);

}  // namespace awcc
