#include "awcc/random.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

namespace {

double density(double x) { return std::exp(-0.5 * x * x); }

// The ziggurat is exact only if its tables are: every layer has the area V,
// the base layer is the rectangle under f(R) plus the tail, and the top layer
// closes at x = 0. A wrong recursion, a wrong R or V, or a shifted index
// breaks one of these identities by far more than rounding.
TEST(Ziggurat, TablesAreLayersOfEqualArea) {
  const auto& t = awcc::ziggurat_tables();
  const double R = awcc::ZigguratTables::R;
  const double tail = std::sqrt(0.5 * std::numbers::pi) * std::erfc(R / std::numbers::sqrt2);
  EXPECT_NEAR(t.V, R * density(R) + tail, 1e-18);
  EXPECT_NEAR(t.x[0] * density(R), t.V, 1e-15 * t.V);
  EXPECT_EQ(t.x[1], R);
  for (std::size_t i = 1; i < 256; ++i) {
    ASSERT_GT(t.x[i], t.x[i + 1]) << i;
    EXPECT_NEAR(t.x[i] * (t.f[i + 1] - t.f[i]), t.V, 1e-11 * t.V) << "layer " << i;
  }
  EXPECT_EQ(t.x[256], 0.0);
  EXPECT_EQ(t.f[256], 1.0);
}

constexpr std::int64_t draws = 10'000'000;

std::vector<double> normals(std::uint64_t seed) {
  awcc::Rng rng(seed, 77);
  std::vector<double> z(static_cast<std::size_t>(draws));
  rng.normals(z);
  return z;
}

// Sample moments m_k = mean(z^k) against the normal's mu_k (0, 1, 0, 3, 0,
// 15). Their sampling error is sqrt((mu_2k - mu_k^2) / n) (the variance of
// z^k over n independent draws), so 6 standard errors is a bound a correct
// generator exceeds with probability about 2e-9 per moment, while a wrong
// layer or tail shifts m_4 or m_6 by many of them (e.g. a tail cut at R
// lowers m_6 by 0.2, 120 standard errors at 1e7 draws).
TEST(Ziggurat, MomentsWithinSixStandardErrors) {
  const auto z = normals(1);
  std::array<long double, 7> sum{};
  for (const double v : z) {
    long double p = 1.0L;
    for (std::size_t k = 1; k <= 6; ++k) {
      p *= v;
      sum[k] += p;
    }
  }
  const std::array<double, 13> mu{1, 0, 1, 0, 3, 0, 15, 0, 105, 0, 945, 0, 10395};
  for (std::size_t k = 1; k <= 6; ++k) {
    const double m = static_cast<double>(sum[k] / draws);
    const double se = std::sqrt((mu[2 * k] - mu[k] * mu[k]) / static_cast<double>(draws));
    EXPECT_LT(std::fabs(m - mu[k]), 6.0 * se) << "moment " << k << ": " << m << " against " << mu[k];
  }
}

// Kolmogorov-Smirnov at 1e7 draws through the probability transform u =
// Phi(z), which is uniform for a correct generator. The statistic is taken
// at the edges of 2^16 equal bins of u: a lower bound of the exact D (it is
// the sup over fewer points), so the test is as valid as the exact one and
// weaker by at most one bin (1.5e-5, against a critical value of 8.5e-4).
// Critical value at alpha = 1e-6: sqrt(ln(2 / alpha) / (2 n)) (the
// asymptotic Kolmogorov tail 2 exp(-2 n D^2)). An error in one layer's
// width moves the CDF by about a layer's probability, 1 / 256 = 3.9e-3.
TEST(Ziggurat, KolmogorovSmirnovAtTenMillionDraws) {
  const auto z = normals(2);
  constexpr std::size_t bins = 1u << 16;
  std::vector<std::int64_t> count(bins, 0);
  for (const double v : z) {
    const double u = 0.5 * std::erfc(-v / std::numbers::sqrt2);
    count[std::min(bins - 1, static_cast<std::size_t>(u * bins))]++;
  }
  double d = 0.0;
  std::int64_t cumulative = 0;
  for (std::size_t b = 0; b < bins; ++b) {
    cumulative += count[b];
    const double edge = static_cast<double>(b + 1) / bins;
    d = std::max(d, std::fabs(static_cast<double>(cumulative) / draws - edge));
  }
  const double critical = std::sqrt(std::log(2.0 / 1e-6) / (2.0 * draws));
  EXPECT_LT(d, critical);
}

// Tails to 5 sigma: the count of |z| > k against n P(|Z| > k) = n erfc(k /
// sqrt 2). The count is binomial; with p small its standard deviation is
// sqrt(n p (1 - p)) and 6 of them (plus one for the discreteness at k = 5,
// where n p = 5.7) bound a correct generator. Beyond R = 3.65 the draws come
// from the tail method alone, so k = 4 and 5 test it: 633 and 5.7 expected.
TEST(Ziggurat, TailsToFiveSigma) {
  const auto z = normals(3);
  for (int k = 1; k <= 5; ++k) {
    std::int64_t beyond = 0;
    for (const double v : z) beyond += std::fabs(v) > k;
    const double p = std::erfc(k / std::numbers::sqrt2);
    const double expected = p * draws;
    const double sd = std::sqrt(draws * p * (1.0 - p));
    EXPECT_LT(std::fabs(static_cast<double>(beyond) - expected), 6.0 * sd + 1.0)
        << "|z| > " << k << ": " << beyond << " against " << expected;
  }
  // The two signs alike beyond R: the sign bit is not tied to the tail.
  std::int64_t above = 0, below = 0;
  for (const double v : z) {
    above += v > awcc::ZigguratTables::R;
    below += v < -awcc::ZigguratTables::R;
  }
  const double sd = std::sqrt(static_cast<double>(above + below));  // of above - below under a fair sign
  EXPECT_LT(std::fabs(static_cast<double>(above - below)), 6.0 * sd);
}

// The block draw is the per-call draw: chunking never changes the numbers.
TEST(Ziggurat, BlocksEqualSingleDraws) {
  awcc::Rng a(11, 5), b(11, 5);
  std::vector<double> block(1000);
  a.normals(std::span<double>(block).first(333));
  a.normals(std::span<double>(block).subspan(333));
  for (std::size_t i = 0; i < block.size(); ++i) ASSERT_EQ(block[i], b.normal()) << i;
}

// The streams of this generator version, pinned: a change to the generator
// that changes the numbers a seed gives must raise awcc::generator_version
// (every synthetic output records it) and then this pin. The pin is a
// checksum of the first 1000 normals and 1000 uniforms of one stream.
TEST(Ziggurat, StreamsPinnedToTheGeneratorVersion) {
  awcc::Rng rng(2026, 3);
  std::uint64_t h = 0;
  for (int i = 0; i < 1000; ++i) {
    const double z = rng.normal();
    h = awcc::mix64(h ^ std::bit_cast<std::uint64_t>(z));
  }
  for (int i = 0; i < 1000; ++i) h = awcc::mix64(h ^ std::bit_cast<std::uint64_t>(rng.uniform()));
  ASSERT_EQ(awcc::generator_version, 2) << "a new generator version: pin its streams here";
  EXPECT_EQ(h, 0x389083fc822a185cull) << std::hex << h;
}

}  // namespace
