#pragma once
// Is a forest's predictive distribution multimodal? (model.hpp, the trust
// rules.) A median is a fair summary of a distribution with one mode; of
// one with two (FSCC right, or FSCC off by a factor of three, say) it can
// fall between them, where the model itself says the truth is least likely.
//
// The test reads the densities between quantiles. For levels a_0 < ... < a_K
// with quantiles q_0 < ... < q_K, interval k holds the density
//   d_k = (a_{k+1} - a_k) / (q_{k+1} - q_k),
// the average of the density over it. If the density f is unimodal
// (non-decreasing up to a mode m, non-increasing after), no interval is
// sparser than the densest interval on each side of it:
//   d_k >= min(max_{i<k} d_i, max_{i>k} d_i).
// (An interval left of m: f is non-decreasing up to its left end, so every
// interval further left has an average at most f there, which is at most
// d_k. Right of m likewise. An interval [a, b] holding m: f >= min(f(a),
// f(b)) on it, and the intervals left of it average at most f(a), those
// right at most f(b).) The dip ratio of a distribution is the least of
//   d_k / min(max_{i<k} d_i, max_{i>k} d_i)
// over the intervals between the quartiles (0.25-0.5 and 0.5-0.75): at
// least 1 when unimodal, and small when a trough with at least a quarter of
// the weight on each side, and the median at one of its ends, is nearly
// empty: then the median misleads. A trough in a tail (a few per cent of the
// weight on one training run, say) leaves the median in the bulk, and the
// interval holds the tail: it is not looked at (on held-out runs it was 2-3
// times as common as a central one; docs/validation.md).
//
// A forest's distribution is a weighted sample of training targets (atoms),
// which no density has; its quantiles are taken from the piecewise-linear
// distribution function that spreads each value's weight evenly between the
// midpoints to its neighbours (the first and last value: as far out as half
// the spacing to their neighbour). Two lone values are so a flat density: the
// test sees modes made of several values, as a forest's are (hundreds of
// training targets, each held by a few trees). A sample of a unimodal density has a
// ratio below 1 by chance; the limit a model applies (model.hpp,
// multimodal_dip_limit) is set from held-out runs so that it rarely fires
// on them (docs/validation.md).
//
// Scale: the ratio of the target form (true / measured) is tested on its
// logarithm, where a factor of 2 above and below weigh alike; the other
// forms on their own scale.

#include <array>
#include <cstddef>

#include "correction/quantile_forest.hpp"

namespace correction {

/// The levels the test reads: those the limit was set on (docs/validation.md),
/// the reported ones before format 7 added 0.05 and 0.95 (model.hpp,
/// correction_levels). Their own list, so that reporting more levels does
/// not move a decided rule.
inline constexpr std::array<double, 7> modality_levels{0.025, 0.1, 0.25, 0.5, 0.75, 0.9, 0.975};

struct Dip {
  double ratio = 1.0;       ///< the least central d_k / min(max left, max right); 1 when neither dips
  std::size_t interval = 0; ///< k of that interval: between modality_levels[k] and [k + 1]
  /// The quantiles of the smoothed distribution at modality_levels, on the
  /// distribution's own scale (not the logarithm).
  std::array<double, 7> quantiles{};
};

/// The dip of a weighted sample (values ascending, weights summing to 1),
/// on the logarithm of its values when `log_scale` (all values positive).
/// A sample of one value has ratio 1.
Dip dip(const WeightedDistribution& d, bool log_scale);

namespace detail {
/// The alpha-quantile of the piecewise-linear smoothing above.
double smoothed_quantile(const WeightedDistribution& d, double alpha);
}  // namespace detail

}  // namespace correction
