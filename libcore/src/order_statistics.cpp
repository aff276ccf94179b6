#include "awcc/order_statistics.hpp"

#include <algorithm>
#include <cmath>

namespace awcc {

double median(std::span<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
  const double upper = v[h];
  if (v.size() % 2) return upper;
  // After selection the lower half holds the smaller values: its largest is the lower middle.
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h)));
}

double quantile_of_sorted(std::span<const double> sorted, double p) {
  if (sorted.empty()) return 0.0;
  const double pos = p * static_cast<double>(sorted.size() - 1);
  const auto k = static_cast<std::size_t>(std::floor(pos));
  const double frac = pos - static_cast<double>(k);
  if (k + 1 >= sorted.size()) return sorted.back();
  return sorted[k] + frac * (sorted[k + 1] - sorted[k]);
}

}  // namespace awcc
