#pragma once
// The steps of the multi-tip solvers (awcc/multi_tip.hpp), for the library's
// own use, its tests and benchmarks; not installed, not a stable interface.

#include <array>

#include "awcc/multi_tip.hpp"

namespace awcc::detail {

/// One combination's solution for one bubble (sizes NaN with Tian).
struct CombinationSolution {
  Vec3 velocity{};
  double diameter_front = 0.0, diameter_rear = 0.0;
  Vec3 normal_front{}, normal_rear{};
  double area_share = 0.0;
};

/// Solves one bubble through one combination: `leading` at tip 0, `trailing`
/// at the combination's three tips in its order. False when degenerate.
bool solve_combination(const TipCombination& combination, const Crossing& leading,
                       const std::array<const Crossing*, 3>& trailing, VelocityAlgorithm algorithm,
                       CombinationSolution& out);

/// Applies the outlier cutoff to the solved bubbles, then fills the
/// statistics, counts, status and message of `result` from result.bubbles
/// (their fates, weights, vectors, sizes and area shares).
void multi_tip_summarise(MultiTipResult& result, const MultiTipOptions& options);

}  // namespace awcc::detail
