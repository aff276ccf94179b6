#pragma once
// Medians and quantiles of samples, written once for the whole toolkit.
//  - median: the middle order statistic, the mean of the two middle ones for
//    an even count (found by selection, O(n); the values are reordered).
//  - quantile_of_sorted: linear interpolation between order statistics,
//    Q(p) = x_(k) + f (x_(k+1) - x_(k)) with k + f = p (n - 1), k from 0
//    (Hyndman and Fan's type 7, as numpy's default).

#include <span>

namespace awcc {

/// Median of `values` (reordered); 0 for an empty sample.
double median(std::span<double> values);

/// Type-7 quantile of ascending `sorted` at p in [0, 1]; 0 for an empty sample.
double quantile_of_sorted(std::span<const double> sorted, double p);

}  // namespace awcc
