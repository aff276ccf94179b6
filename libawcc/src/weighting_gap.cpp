#include "awcc/weighting_gap.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

namespace awcc {

namespace {

// Student's t, 97.5 % quantiles of 1-9 degrees of freedom (blocks - 1; scipy.stats.t.ppf).
constexpr double kT975[] = {12.7062047364, 4.3026527299, 3.1824463053, 2.7764451052, 2.5705818366,
                            2.4469118488,  2.3646242510, 2.3060041350, 2.2621571627};
static_assert(std::size(kT975) == weighting_gap_blocks - 1, "a quantile for every number of blocks - 1");

struct Sums {
  double n = 0, u = 0, w = 0, wu = 0;
  [[nodiscard]] double gap() const { return (u / n) / (wu / w) - 1.0; }
  Sums operator-(const Sums& o) const { return {n - o.n, u - o.u, w - o.w, wu - o.wu}; }
};

}  // namespace

WeightingGap weighting_gap(std::span<const double> velocities, std::span<const double> durations, double tu) {
  const std::size_t n = std::min(velocities.size(), durations.size());
  WeightingGap out;
  if (n < 2) return out;
  const std::size_t blocks = std::min<std::size_t>(weighting_gap_blocks, n);
  std::vector<Sums> block(blocks);
  Sums all;
  // Block b holds windows [b n / B, (b + 1) n / B).
  for (std::size_t b = 0; b < blocks; ++b) {
    for (std::size_t i = b * n / blocks; i < (b + 1) * n / blocks; ++i) {
      const double u = velocities[i], w = durations[i];
      block[b].n += 1, block[b].u += u, block[b].w += w, block[b].wu += w * u;
      all.n += 1, all.u += u, all.w += w, all.wu += w * u;
    }
  }
  out.value = all.gap();
  std::vector<double> without(blocks);
  double mean = 0.0;
  for (std::size_t b = 0; b < blocks; ++b) mean += (without[b] = (all - block[b]).gap());
  mean /= static_cast<double>(blocks);
  double ss = 0.0;
  for (double g : without) ss += (g - mean) * (g - mean);
  const double k = static_cast<double>(blocks);
  const double se = std::sqrt((k - 1.0) / k * ss);
  // Fewer windows than blocks: one window a block, and a wider quantile.
  const double t = kT975[blocks - 2];
  out.ci95 = {out.value - t * se, out.value + t * se};
  out.allowance = time_arrival_gap_allowance * tu * tu;
  out.along_flow = out.ci95.lower > out.allowance;
  return out;
}

}  // namespace awcc
