#pragma once
// Shared by the interval paths of FSCC and AWCC (not installed).
//
// The overlap of an air interval [a0, a1) of x with an air interval [b0, b1)
// of y shifted back by k, as a function of the lag k, is a trapezoid whose
// second difference is +1 at b0 - a1, -1 at b0 - a0 and at b1 - a1, +1 at
// b1 - a0. Summing these impulses over pairs and taking two prefix sums gives
// the sum of overlaps, sum_t x(t) y(t + k), exactly and in integers.

#include <cstdint>
#include <vector>

namespace awcc::detail {

template <class Count>
struct OverlapImpulses {
  std::int64_t k_min, k_max;
  std::vector<Count>& impulse;     ///< per lag of [k_min, k_max], zeroed by the caller
  std::uint64_t* mark = nullptr;   ///< when set, a bitset of the lags holding an impulse
  std::int64_t slope = 0;          ///< slope before k_min from impulses before it
  std::int64_t value = 0;          ///< overlap sum at k_min from impulses before it

  void add(std::int64_t k, int weight) {
    if (k > k_max) return;
    if (k < k_min) {
      // An impulse before k_min adds its weight to every later slope, so
      // weight (k_min - k) to the value at k_min.
      slope += weight;
      value += weight * (k_min - k);
      return;
    }
    const auto i = static_cast<std::size_t>(k - k_min);
    impulse[i] += static_cast<Count>(weight);
    if (mark) mark[i >> 6] |= std::uint64_t{1} << (i & 63);
  }

  /// One pair of air intervals; pairs whose trapezoid ends at or before
  /// k_min or starts after k_max add nothing in range and are skipped.
  void add_pair(std::int64_t a0, std::int64_t a1, std::int64_t b0, std::int64_t b1) {
    if (b1 - a0 <= k_min || b0 - a1 > k_max) return;
    add(b0 - a1, +1);
    add(b0 - a0, -1);
    add(b1 - a1, -1);
    add(b1 - a0, +1);
  }
};

}  // namespace awcc::detail
