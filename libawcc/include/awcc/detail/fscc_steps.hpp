#pragma once
// The steps of FSCC (awcc/fscc.hpp), for the library's own use, its tests and
// benchmarks; not installed, not a stable interface.

#include <cstdint>
#include <vector>

#include "awcc/air_intervals.hpp"
#include "awcc/fft.hpp"

namespace awcc::detail {

/// How lagged products are computed: both exact; automatic picks the cheaper
/// (pairs of air intervals within the lag range, or block FFTs).
enum class ProductPath { automatic, fft, intervals };

/// S(k) = sum over t in [t0, t1) of X(t) Y(t + k), k in [k_min, k_max], for
/// 0/1 signals given as intervals (Y is 0 outside its record).
std::vector<double> lagged_products(const AirIntervals& x, const AirIntervals& y, std::int64_t t0, std::int64_t t1,
                                    std::int64_t k_min, std::int64_t k_max, FftPlanCache& plans,
                                    ProductPath path = ProductPath::automatic);

/// Air samples of a signal within [a, b).
std::int64_t air_samples_in(const AirIntervals& signal, std::int64_t a, std::int64_t b);

}  // namespace awcc::detail
