#include "correction/modality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace correction {

namespace detail {

double smoothed_quantile(const WeightedDistribution& d, double alpha) {
  const auto& v = d.values;
  const auto n = v.size();
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  if (n == 1) return v.front();
  double below = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double lo = i == 0 ? v[0] - 0.5 * (v[1] - v[0]) : 0.5 * (v[i - 1] + v[i]);
    const double hi = i + 1 == n ? v[n - 1] + 0.5 * (v[n - 1] - v[n - 2]) : 0.5 * (v[i] + v[i + 1]);
    if (below + d.weights[i] >= alpha) return lo + (hi - lo) * std::clamp((alpha - below) / d.weights[i], 0.0, 1.0);
    below += d.weights[i];
  }
  return v.back() + 0.5 * (v[n - 1] - v[n - 2]);
}

}  // namespace detail

Dip dip(const WeightedDistribution& d, bool log_scale) {
  // Values apart by rounding only (targets t = y_true - y_measured of one
  // truth, say) are one value: spread between them, their weight would be
  // a density without bound.
  WeightedDistribution scaled;
  for (std::size_t i = 0; i < d.values.size(); ++i) {
    const double x = log_scale ? std::log(d.values[i]) : d.values[i];
    if (!scaled.values.empty() && x - scaled.values.back() <= 1e-9 * std::max(1.0, std::fabs(x))) {
      scaled.weights.back() += d.weights[i];
    } else {
      scaled.values.push_back(x);
      scaled.weights.push_back(d.weights[i]);
    }
  }
  Dip out;
  std::array<double, modality_levels.size()> q{};
  for (std::size_t k = 0; k < q.size(); ++k) {
    q[k] = detail::smoothed_quantile(scaled, modality_levels[k]);
    out.quantiles[k] = log_scale ? std::exp(q[k]) : q[k];
  }
  if (scaled.values.size() < 2) return out;
  constexpr std::size_t intervals = modality_levels.size() - 1;
  std::array<double, intervals> density{};
  for (std::size_t k = 0; k < intervals; ++k) {
    // The smoothed distribution function rises everywhere on its support: every width is positive.
    density[k] = (modality_levels[k + 1] - modality_levels[k]) / (q[k + 1] - q[k]);
  }
  for (std::size_t k = 1; k + 1 < intervals; ++k) {
    if (modality_levels[k] < 0.25 || modality_levels[k + 1] > 0.75) continue;  // a tail's trough: the median stands
    const double left = *std::max_element(density.begin(), density.begin() + static_cast<std::ptrdiff_t>(k));
    const double right = *std::max_element(density.begin() + static_cast<std::ptrdiff_t>(k) + 1, density.end());
    const double ratio = density[k] / std::min(left, right);
    if (ratio < out.ratio) {
      out.ratio = ratio;
      out.interval = k;
    }
  }
  return out;
}

}  // namespace correction
