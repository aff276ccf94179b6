// 95 % confidence intervals of the void fraction c and the bubble count rate
// F (phase_statistics.hpp): hand-listed chords against a long-double
// evaluation of the documented formulas, the clamps to [0, 1] and [0, inf),
// the minimum number of chords, and the coverage on records of known c and F.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "awcc/phase_statistics.hpp"

namespace {

using awcc::AirIntervals;

// The documented formulas in long double, n cycles, chord times in seconds:
//   Var(c) = ((1 - c)^2 Var(a) + c^2 Var(w)) / (n m^2), m = E[a] + E[w];
//   Var(F) / F^2 = (Var(a) + Var(w)) / (m^2 n);
// sample variances with n - 1; bounds c -/+ 1.96 se and F -/+ 1.96 se.
struct ExpectedPhases {
  long double c, c_lower, c_upper;  // unclamped
  long double f, f_lower, f_upper;  // unclamped
};

long double mean(const std::vector<long double>& v) {
  long double s = 0;
  for (auto x : v) s += x;
  return s / static_cast<long double>(v.size());
}

long double sample_variance(const std::vector<long double>& v) {
  const long double m = mean(v);
  long double s = 0;
  for (auto x : v) s += (x - m) * (x - m);
  return s / static_cast<long double>(v.size() - 1);
}

// air, water: complete chords in samples; air_total: air samples of the record.
ExpectedPhases expected(const std::vector<long double>& air_samples, const std::vector<long double>& water_samples,
                  long double air_total, long double sample_count, long double fs) {
  std::vector<long double> a, w;
  for (auto x : air_samples) a.push_back(x / fs);
  for (auto x : water_samples) w.push_back(x / fs);
  const long double n = static_cast<long double>(a.size());
  const long double c = air_total / sample_count, duration = sample_count / fs;
  const long double m = mean(a) + mean(w), va = sample_variance(a), vw = sample_variance(w);
  const long double se_c = std::sqrt(((1 - c) * (1 - c) * va + c * c * vw) / (n * m * m));
  const long double f = n / duration;
  const long double se_f = f * std::sqrt((va + vw) / (m * m * n));
  return {c, c - 1.96L * se_c, c + 1.96L * se_c, f, f - 1.96L * se_f, f + 1.96L * se_f};
}

void expect_relative(double got, long double want, const char* what) {
  EXPECT_LE(std::fabs(static_cast<long double>(got) - want), 1e-12L * std::fabs(want))
      << what << ": got " << got << ", expected " << static_cast<double>(want);
}

AirIntervals record(std::vector<awcc::AirInterval> intervals, std::int64_t samples, double fs) {
  AirIntervals s;
  s.fs = fs;
  s.sample_count = samples;
  s.intervals = std::move(intervals);
  EXPECT_TRUE(s.check().empty()) << s.check();
  return s;
}

TEST(PhaseIntervals, VoidFractionAndCountRateIntervalsMatchTheFormulasByHand) {
  // 400 samples at 1 kHz (0.4 s). Air: [0, 3) cut by the start, [10, 15),
  // [30, 42), [60, 67), [100, 109), [150, 154), [180, 190), [215, 221),
  // [250, 262), [290, 298), [330, 333), [360, 370), [395, 400) cut by the end.
  // Air samples 3 + 5 + 12 + 7 + 9 + 4 + 10 + 6 + 12 + 8 + 3 + 10 + 5 = 94:
  // c = 0.235. Complete air chords 5, 12, 7, 9, 4, 10, 6, 12, 8, 3, 10
  // samples (n = 11, F = 11 / 0.4 s = 27.5 / s); water chords between air
  // chords 7, 15, 18, 33, 41, 26, 25, 29, 28, 32, 27, 25 samples.
  const auto s = record({{0, 3}, {10, 15}, {30, 42}, {60, 67}, {100, 109}, {150, 154}, {180, 190}, {215, 221},
                         {250, 262}, {290, 298}, {330, 333}, {360, 370}, {395, 400}},
                        400, 1000.0);
  const auto e = expected({5, 12, 7, 9, 4, 10, 6, 12, 8, 3, 10}, {7, 15, 18, 33, 41, 26, 25, 29, 28, 32, 27, 25}, 94,
                          400, 1000);
  const auto p = awcc::phase_statistics(s);
  ASSERT_EQ(p.void_fraction, 0.235);
  ASSERT_EQ(p.bubble_count_rate, 27.5);
  // Neither bound is clamped here (about 0.179-0.291 and 22.9-32.1 / s).
  ASSERT_GT(e.c_lower, 0.0L);
  ASSERT_LT(e.c_upper, 1.0L);
  ASSERT_GT(e.f_lower, 0.0L);
  expect_relative(p.void_fraction_ci95.lower, e.c_lower, "c lower");
  expect_relative(p.void_fraction_ci95.upper, e.c_upper, "c upper");
  expect_relative(p.bubble_count_rate_ci95.lower, e.f_lower, "F lower");
  expect_relative(p.bubble_count_rate_ci95.upper, e.f_upper, "F upper");
}

TEST(PhaseIntervals, SameAtAnotherSamplingRateAndWithoutEdgeChords) {
  // 2500 samples at 20 kHz (0.125 s). Air [100, 180), [400, 401), [900, 1150),
  // [1400, 1433), [1700, 1760), [2000, 2090), [2300, 2340): all complete,
  // 80, 1, 250, 33, 60, 90, 40 samples (n = 7, F = 56 / s); water 220, 499,
  // 250, 267, 240, 210; air 554 samples, c = 0.2216.
  const auto s = record({{100, 180}, {400, 401}, {900, 1150}, {1400, 1433}, {1700, 1760}, {2000, 2090}, {2300, 2340}},
                        2500, 20e3);
  const auto e = expected({80, 1, 250, 33, 60, 90, 40}, {220, 499, 250, 267, 240, 210}, 554, 2500, 20e3);
  const auto p = awcc::phase_statistics(s);
  ASSERT_EQ(p.bubble_count_rate, 56.0);
  ASSERT_GT(e.c_lower, 0.0L);
  ASSERT_LT(e.c_upper, 1.0L);
  ASSERT_GT(e.f_lower, 0.0L);
  expect_relative(p.void_fraction_ci95.lower, e.c_lower, "c lower");
  expect_relative(p.void_fraction_ci95.upper, e.c_upper, "c upper");
  expect_relative(p.bubble_count_rate_ci95.lower, e.f_lower, "F lower");
  expect_relative(p.bubble_count_rate_ci95.upper, e.f_upper, "F upper");
}

TEST(PhaseIntervals, VoidFractionLowerBoundIsClampedAtZero) {
  // 1000 samples at 1 kHz: air chords 1, 30, 1 samples, water 399, 370; c =
  // 0.032. The chords vary so much that c - 1.96 se < 0: the bound is 0.
  const auto s = record({{100, 101}, {500, 530}, {900, 901}}, 1000, 1000.0);
  const auto e = expected({1, 30, 1}, {399, 370}, 32, 1000, 1000);
  ASSERT_LT(e.c_lower, 0.0L);
  ASSERT_LT(e.c_upper, 1.0L);
  const auto p = awcc::phase_statistics(s);
  EXPECT_EQ(p.void_fraction_ci95.lower, 0.0);
  expect_relative(p.void_fraction_ci95.upper, e.c_upper, "c upper");
}

TEST(PhaseIntervals, VoidFractionUpperBoundIsClampedAtOne) {
  // 1000 samples at 1 kHz: air chords 399, 1, 497, water 1, 100; c = 0.897,
  // c + 1.96 se > 1: the bound is 1.
  const auto s = record({{1, 400}, {401, 402}, {502, 999}}, 1000, 1000.0);
  const auto e = expected({399, 1, 497}, {1, 100}, 897, 1000, 1000);
  ASSERT_GT(e.c_upper, 1.0L);
  ASSERT_GT(e.c_lower, 0.0L);
  const auto p = awcc::phase_statistics(s);
  EXPECT_EQ(p.void_fraction_ci95.upper, 1.0);
  expect_relative(p.void_fraction_ci95.lower, e.c_lower, "c lower");
}

TEST(PhaseIntervals, CountRateLowerBoundIsClampedAtZeroAndTheUpperIsNot) {
  // 2000 samples at 1 kHz: three 1-sample bubbles, water chords 1 and 1000
  // samples: CV^2 = Var(w) / m^2 ~ 2 over n = 3 cycles, F - 1.96 se < 0.
  const auto s = record({{10, 11}, {12, 13}, {1013, 1014}}, 2000, 1000.0);
  const auto e = expected({1, 1, 1}, {1, 1000}, 3, 2000, 1000);
  ASSERT_LT(e.f_lower, 0.0L);
  const auto p = awcc::phase_statistics(s);
  EXPECT_EQ(p.bubble_count_rate, 1.5);
  EXPECT_EQ(p.bubble_count_rate_ci95.lower, 0.0);
  expect_relative(p.bubble_count_rate_ci95.upper, e.f_upper, "F upper");
}

TEST(PhaseIntervals, TwoCompleteAirAndTwoWaterChordsAreTheFewestThatGiveAnInterval) {
  // [0, 5) is cut by the start: complete air chords 10 and 10 (no spread),
  // water chords 5 and 10: an interval, from the water chords' spread alone.
  const auto two = record({{0, 5}, {10, 20}, {30, 40}}, 100, 100.0);
  const auto e = expected({10, 10}, {5, 10}, 25, 100, 100);
  const auto p = awcc::phase_statistics(two);
  EXPECT_LT(p.void_fraction_ci95.lower, p.void_fraction);
  expect_relative(p.void_fraction_ci95.lower, e.c_lower, "c lower");
  expect_relative(p.bubble_count_rate_ci95.upper, e.f_upper, "F upper");
  // Two complete air chords (of different lengths, so that a spread
  // exists) but one water chord: no interval, [c, c].
  const auto one_water = awcc::phase_statistics(record({{10, 20}, {30, 45}}, 100, 100.0));
  EXPECT_EQ(one_water.void_fraction_ci95.lower, 0.25);
  EXPECT_EQ(one_water.void_fraction_ci95.upper, 0.25);
  EXPECT_EQ(one_water.bubble_count_rate_ci95.lower, 2.0);
  EXPECT_EQ(one_water.bubble_count_rate_ci95.upper, 2.0);
  // Two water chords but one complete air chord ([0, 5) and [30, 100) are
  // cut by the record's ends): no interval.
  const auto one_air = awcc::phase_statistics(record({{0, 5}, {10, 20}, {30, 100}}, 100, 100.0));
  EXPECT_EQ(one_air.bubble_count_rate, 1.0);
  EXPECT_EQ(one_air.void_fraction_ci95.lower, one_air.void_fraction);
  EXPECT_EQ(one_air.void_fraction_ci95.upper, one_air.void_fraction);
  EXPECT_EQ(one_air.bubble_count_rate_ci95.lower, 1.0);
  EXPECT_EQ(one_air.bubble_count_rate_ci95.upper, 1.0);
}

TEST(PhaseIntervals, CoverTheTrueVoidFractionAndCountRateIn95PercentOfRecords) {
  // Records of independent chords: air 1 + Geometric(0.2) samples (mean 5),
  // water 1 + Geometric(1/45) (mean 45), 50,000 samples at 1 kHz (about
  // 1000 cycles). True c = 5 / 50 = 0.1, true F = 1000 / 50 = 20 / s. The
  // intervals are asymptotic; with 1000 cycles their coverage is 0.95 to well
  // within the binomial spread of 1000 records: sd = sqrt(0.95 x 0.05 / 1000)
  // = 0.0069, so the observed coverage must lie in 0.95 +/- 3 sd.
  std::mt19937_64 rng(2024);
  std::geometric_distribution<int> air(0.2), water(1.0 / 45.0);
  const int records = 1000;
  const std::int64_t n = 50'000;
  int c_covered = 0, f_covered = 0;
  for (int r = 0; r < records; ++r) {
    AirIntervals s;
    s.fs = 1000.0;
    s.sample_count = n;
    std::int64_t t = 1 + water(rng);
    while (t < n) {
      const std::int64_t stop = std::min(n, t + 1 + air(rng));
      s.intervals.push_back({t, stop});
      t = stop + 1 + water(rng);
    }
    const auto p = awcc::phase_statistics(s);
    c_covered += p.void_fraction_ci95.lower <= 0.1 && 0.1 <= p.void_fraction_ci95.upper;
    f_covered += p.bubble_count_rate_ci95.lower <= 20.0 && 20.0 <= p.bubble_count_rate_ci95.upper;
  }
  const double sd = std::sqrt(0.95 * 0.05 / records);
  EXPECT_NEAR(static_cast<double>(c_covered) / records, 0.95, 3 * sd);
  EXPECT_NEAR(static_cast<double>(f_covered) / records, 0.95, 3 * sd);
}

}  // namespace
