// Tests of awcc/weighting_gap.hpp: the gap's identities, its block jackknife
// against a naive long-double one, and the flag at and around its limit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "awcc/weighting_gap.hpp"

namespace {

// Equal window durations: the weighted and plain means coincide, g = 0 and
// every block's g is 0, so the interval has no width.
TEST(WeightingGap, EqualDurationsGiveZero) {
  const std::vector<double> u{9.0, 11.0, 10.5, 8.7, 12.1, 10.0, 9.9, 10.2, 11.4, 8.8, 10.1, 9.5};
  const std::vector<double> w(u.size(), 0.02);
  const auto g = awcc::weighting_gap(u, w, 0.12);
  EXPECT_NEAR(g.value, 0.0, 1e-15);
  EXPECT_NEAR(g.ci95.lower, 0.0, 1e-15);
  EXPECT_NEAR(g.ci95.upper, 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(g.allowance, awcc::time_arrival_gap_allowance * 0.12 * 0.12);
  EXPECT_FALSE(g.along_flow);
}

// Windows of equal bubble counts spaced along the flow last T_W = s / u:
// the weighted mean is the harmonic mean and g = AM / HM - 1, which for
// lognormal u with sd of ln u = sigma is exp(sigma^2) - 1 (AM = e^(m +
// s^2/2), HM = e^(m - s^2/2)): about Tu^2. 20,000 windows put the jackknife
// interval well inside the gap, above 0.5 Tu^2.
TEST(WeightingGap, ArrivalsAlongTheFlowAreFlagged) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> z(0.0, 0.2);
  std::vector<double> u, w;
  for (int i = 0; i < 20000; ++i) {
    u.push_back(10.0 * std::exp(z(rng)));
    w.push_back(0.05 / u.back());
  }
  const auto g = awcc::weighting_gap(u, w, 0.2);
  EXPECT_NEAR(g.value, std::expm1(0.04), 0.004);  // the sampling sd of g here is about 0.0006
  EXPECT_TRUE(g.along_flow);
  // The same velocities with durations that ignore them (arrivals in time).
  std::vector<double> in_time(u.size(), 0.005);
  EXPECT_FALSE(awcc::weighting_gap(u, in_time, 0.2).along_flow);
}

// The block jackknife, written naively in long double: blocks of
// consecutive windows, block b = windows [b n / B, (b + 1) n / B).
long double naive_gap(const std::vector<double>& u, const std::vector<double>& w, std::size_t skip_first,
                      std::size_t skip_last) {
  long double n = 0, su = 0, sw = 0, swu = 0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    if (i >= skip_first && i < skip_last) continue;
    n += 1, su += u[i], sw += w[i], swu += static_cast<long double>(w[i]) * u[i];
  }
  return (su / n) / (swu / sw) - 1;
}

TEST(WeightingGap, JackknifeMatchesANaiveOne) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> uni(0.5, 1.5);
  for (std::size_t n : {10u, 23u, 97u, 1000u}) {
    std::vector<double> u, w;
    for (std::size_t i = 0; i < n; ++i) {
      u.push_back(5.0 * uni(rng));
      w.push_back(0.01 * uni(rng) / (0.5 + 0.5 * u.back() / 5.0));
    }
    const std::size_t blocks = 10;
    std::vector<long double> g;
    long double mean = 0;
    for (std::size_t b = 0; b < blocks; ++b) {
      g.push_back(naive_gap(u, w, b * n / blocks, (b + 1) * n / blocks));
      mean += g.back();
    }
    mean /= blocks;
    long double ss = 0;
    for (auto x : g) ss += (x - mean) * (x - mean);
    const long double se = std::sqrt(9.0L / 10.0L * ss);
    const long double value = naive_gap(u, w, 0, 0);
    const auto got = awcc::weighting_gap(u, w, 0.3);
    EXPECT_NEAR(got.value, static_cast<double>(value), 1e-12) << n;
    EXPECT_NEAR(got.ci95.lower, static_cast<double>(value - 2.2621571627L * se), 1e-9) << n;
    EXPECT_NEAR(got.ci95.upper, static_cast<double>(value + 2.2621571627L * se), 1e-9) << n;
  }
}

// The flag at its limit: the interval's lower end against kappa Tu^2, Tu set
// so that the allowance sits just below and just above that end.
TEST(WeightingGap, FlagAtAndAroundItsLimit) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> z(0.0, 0.25);
  std::vector<double> u, w;
  for (int i = 0; i < 5000; ++i) {
    u.push_back(8.0 * std::exp(z(rng)));
    w.push_back(0.04 / u.back());
  }
  const auto g = awcc::weighting_gap(u, w, 0.25);
  ASSERT_GT(g.ci95.lower, 0.0);
  const double tu_at_limit = std::sqrt(g.ci95.lower / awcc::time_arrival_gap_allowance);
  EXPECT_TRUE(awcc::weighting_gap(u, w, tu_at_limit * (1 - 1e-9)).along_flow);
  EXPECT_FALSE(awcc::weighting_gap(u, w, tu_at_limit * (1 + 1e-9)).along_flow);
}

TEST(WeightingGap, FewerWindowsThanBlocksWidenTheQuantile) {
  const std::vector<double> u{9.0, 11.0, 10.5, 8.7, 12.1}, w{0.011, 0.009, 0.010, 0.012, 0.008};
  const auto g = awcc::weighting_gap(u, w, 0.1);
  EXPECT_GT(g.ci95.upper - g.ci95.lower, 0.0);
  EXPECT_LE(g.ci95.lower, g.value);
  EXPECT_GE(g.ci95.upper, g.value);
  const std::vector<double> one{10.0};
  EXPECT_EQ(awcc::weighting_gap(one, one, 0.1).value, 0.0);
}

}  // namespace
