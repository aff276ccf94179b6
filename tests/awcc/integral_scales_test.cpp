// FSCC integral time scales (fscc.hpp): Txx = integral of R11 from lag 0 to
// its first zero, Txy = integral of R12 from its peak to its first zero,
// against a naive long-double computation of the correlation functions and
// of the integrals.
//
// The rule fscc.cpp uses (replicated independently below): the trapezoid
// rule between consecutive lags, and at the first lag whose value is <= 0 the
// zero is placed by linear interpolation between the last positive value and
// it, and the area of that last piece is the triangle up to the interpolated
// zero. The integral is in samples, divided by fs.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "awcc/fscc.hpp"
#include "random_signals.hpp"
#include "signal_builders.hpp"

namespace {

using awcc::AirIntervals;

// R(k) = sum over t with t and t + k in the record of (x_t - mx)(y_{t+k} - my),
// over sqrt(sum (x - mx)^2 sum (y - my)^2), for k = k_min..k_max.
std::vector<long double> naive_correlation(const AirIntervals& xs, const AirIntervals& ys, std::int64_t k_min,
                                           std::int64_t k_max) {
  const auto x = awcc::to_dense(xs), y = awcc::to_dense(ys);
  const auto n = static_cast<std::int64_t>(x.size());
  long double mx = 0, my = 0;
  for (std::int64_t t = 0; t < n; ++t) {
    mx += x[static_cast<std::size_t>(t)];
    my += y[static_cast<std::size_t>(t)];
  }
  mx /= n;
  my /= n;
  long double qx = 0, qy = 0;
  for (std::int64_t t = 0; t < n; ++t) {
    qx += (x[static_cast<std::size_t>(t)] - mx) * (x[static_cast<std::size_t>(t)] - mx);
    qy += (y[static_cast<std::size_t>(t)] - my) * (y[static_cast<std::size_t>(t)] - my);
  }
  std::vector<long double> r;
  for (std::int64_t k = k_min; k <= k_max; ++k) {
    long double s = 0;
    for (std::int64_t t = 0; t < n; ++t) {
      if (t + k < 0 || t + k >= n) continue;
      s += (x[static_cast<std::size_t>(t)] - mx) * (y[static_cast<std::size_t>(t + k)] - my);
    }
    r.push_back(s / std::sqrt(qx * qy));
  }
  return r;
}

// The area under the linear interpolant of r from index `from` to the first
// zero crossing after it, in samples; empty when r stays positive. The
// crossing lies at z - 1 + r[z-1] / (r[z-1] - r[z]), z the first index after
// `from` with r[z] <= 0; the area is that of trapezoids [i, i + 1] up to z - 1
// plus the triangle of height r[z-1] from z - 1 to the crossing.
struct ZeroCrossing {
  long double area;
  long double zero;   // fractional index of the zero
  long double gap;    // |r| of the two values bracketing it: how clear the crossing is
};
std::optional<ZeroCrossing> area_to_first_zero(const std::vector<long double>& r, std::size_t from) {
  std::size_t z = from + 1;
  while (z < r.size() && r[z] > 0) ++z;
  if (z >= r.size()) return std::nullopt;
  long double area = 0;
  for (std::size_t i = from; i + 1 < z; ++i) area += (r[i] + r[i + 1]) / 2;
  const long double width = r[z - 1] / (r[z - 1] - r[z]);
  area += r[z - 1] * width / 2;
  return ZeroCrossing{area, static_cast<long double>(z - 1) + width, std::min(std::fabs(r[z - 1]), std::fabs(r[z]))};
}

void expect_relative(double got, long double want, const char* what) {
  EXPECT_LE(std::fabs(static_cast<long double>(got) - want), 1e-12L * std::fabs(want))
      << what << ": got " << got << ", expected " << static_cast<double>(want);
}

TEST(IntegralScales, TxxAndTxyMatchNaiveCorrelationsAndTrapezoids) {
  // 4000 samples at 2 kHz; the trailing tip sees the leading tip's bubbles 7
  // samples later plus bubbles of its own, so that R12 is not R11 shifted and
  // Txy differs from Txx.
  const double fs = 2000.0;
  const auto x = pdp_test::telegraph(4000, 51, fs, 12, 40, 2);
  const auto own = pdp_test::telegraph(4000, 52, fs, 6, 120, 2);
  auto y = pdp_test::shifted(x, 7);
  y.intervals.insert(y.intervals.end(), own.intervals.begin(), own.intervals.end());
  awcc::normalise(y.intervals);
  ASSERT_TRUE(y.check().empty());

  awcc::FsccOptions o;
  o.max_lag = 0.05;  // 100 lags
  const auto r = awcc::fscc(x, y, 1.0, o);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.lag_samples, 7);
  ASSERT_EQ(r.r11_first_lag, 0);
  ASSERT_EQ(r.r12_first_lag, -100);
  ASSERT_EQ(r.r11.size(), 101u);
  ASSERT_EQ(r.r12.size(), 201u);

  const auto r11 = naive_correlation(x, x, 0, 100);
  const auto r12 = naive_correlation(x, y, -100, 100);
  for (std::size_t i = 0; i < r11.size(); ++i) ASSERT_NEAR(r.r11[i], static_cast<double>(r11[i]), 1e-13) << i;
  for (std::size_t i = 0; i < r12.size(); ++i) ASSERT_NEAR(r.r12[i], static_cast<double>(r12[i]), 1e-13) << i;

  const auto xx = area_to_first_zero(r11, 0);
  const auto xy = area_to_first_zero(r12, 107);  // the peak, lag 7
  ASSERT_TRUE(xx && xy);
  // The first zeros are clear: rounding cannot move them to another lag.
  ASSERT_GT(xx->gap, 1e-9L);
  ASSERT_GT(xy->gap, 1e-9L);
  // Both functions cross zero a few lags on, and Txy is not Txx.
  ASSERT_GT(xx->zero, 2.0L);
  ASSERT_GT(xy->zero, 107.0L + 2.0L);
  ASSERT_GT(std::fabs(xx->area - xy->area), 0.01L * xx->area);

  ASSERT_TRUE(r.txx.has_value());
  ASSERT_TRUE(r.txy.has_value());
  expect_relative(*r.txx, xx->area / fs, "Txx");
  expect_relative(*r.txy, xy->area / fs, "Txy");
}

TEST(IntegralScales, SameOverSeveralDelaysAndSeeds) {
  const double fs = 1000.0;
  for (unsigned seed : {61u, 62u, 63u}) {
    for (std::int64_t delay : {1, 4, 13}) {
      const auto x = pdp_test::telegraph(3000, seed, fs, 8, 30, 1);
      const auto noise = pdp_test::telegraph(3000, seed + 100, fs, 4, 200, 1);
      auto y = pdp_test::shifted(x, delay);
      y.intervals.insert(y.intervals.end(), noise.intervals.begin(), noise.intervals.end());
      awcc::normalise(y.intervals);
      awcc::FsccOptions o;
      o.max_lag = 0.06;  // 60 lags
      const auto r = awcc::fscc(x, y, 1.0, o);
      ASSERT_TRUE(r.ok()) << r.message;
      ASSERT_EQ(r.lag_samples, delay) << "seed " << seed;
      const auto r11 = naive_correlation(x, x, 0, 60);
      const auto r12 = naive_correlation(x, y, -60, 60);
      const auto xx = area_to_first_zero(r11, 0);
      const auto xy = area_to_first_zero(r12, static_cast<std::size_t>(60 + delay));
      ASSERT_TRUE(xx && xy) << "seed " << seed << " delay " << delay;
      ASSERT_GT(xx->gap, 1e-9L);
      ASSERT_GT(xy->gap, 1e-9L);
      ASSERT_TRUE(r.txx && r.txy);
      expect_relative(*r.txx, xx->area / fs, "Txx");
      expect_relative(*r.txy, xy->area / fs, "Txy");
    }
  }
}

TEST(IntegralScales, MissingWhenTheFunctionNeverReachesZeroWithinTheLagsSearched) {
  // Chords of 200-400 samples: R11 stays positive over 5 lags; no Txx
  // (rather than an integral cut at the end of the lags searched).
  const double fs = 1000.0;
  const auto x = pdp_test::telegraph(20'000, 71, fs, 200, 200, 200);
  const auto y = pdp_test::shifted(x, 2);
  awcc::FsccOptions o;
  o.max_lag = 0.005;
  const auto r = awcc::fscc(x, y, 1.0, o);
  ASSERT_EQ(r.r11.size(), 6u);
  for (double v : r.r11) ASSERT_GT(v, 0.0);
  EXPECT_FALSE(r.txx.has_value());
  EXPECT_FALSE(r.txy.has_value());
  // With lags enough to reach the first zero, both exist.
  o.max_lag = 1.0;
  const auto wide = awcc::fscc(x, y, 1.0, o);
  EXPECT_TRUE(wide.txx.has_value());
  EXPECT_TRUE(wide.txy.has_value());
}

TEST(IntegralScales, ZeroReachedExactlyAtALagEndsTheIntegralThere) {
  // Sample t of the leading tip is position t + 1 of the pattern 0000 1111,
  // over 800 samples: mean 1/2 exactly, q = sum (x - 1/2)^2 = 200, and the
  // products (x_t - 1/2)(x_{t+k} - 1/2) are +1/4 where the two samples agree,
  // -1/4 where they differ. Lag 1: of the 799 pairs, those with t mod 8 in
  // {2, 6} differ (200), 599 agree: R11(1) = (599 - 200) / 4 / 200 = 0.49875.
  // Lag 2: of the 798 pairs, t mod 8 in {1, 2, 5, 6} differ (100 + 100 + 100
  // + 99 = 399), 399 agree: R11(2) = 0 exactly. The integral stops at lag 2:
  // trapezoids (1 + 0.49875) / 2 + (0.49875 + 0) / 2 = 0.99875 samples (the
  // final triangle has width 1 when the zero is a sample).
  const double fs = 1000.0;
  const auto x = pdp_test::square_wave(800, 4, 4, fs, 1);
  awcc::FsccOptions o;
  o.max_lag = 0.02;
  const auto r = awcc::fscc(x, pdp_test::shifted(x, 1), 1.0, o);
  ASSERT_EQ(r.r11[0], 1.0);
  ASSERT_EQ(r.r11[1], 0.49875);
  ASSERT_EQ(r.r11[2], 0.0);
  ASSERT_TRUE(r.txx.has_value());
  EXPECT_DOUBLE_EQ(*r.txx, 0.99875 / fs);
}

}  // namespace
