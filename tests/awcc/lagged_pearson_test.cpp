// LaggedPearson (awcc/lagged_pearson.hpp) and FSCC of raw voltages
// (RawCorrelation, awcc/fscc.hpp) against naive long-double sums of the
// definitions: Pearson's coefficient over a fixed window of x, and Felder's
// average of the segment coefficients.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "awcc/fscc.hpp"
#include "awcc/lagged_pearson.hpp"

namespace {

// A noisy two-level voltage (air 0.3 V, water 4.1 V, noise 0.02 V) with
// random chords, and the same delayed by `delay` samples with its own noise.
struct Voltages {
  std::vector<double> leading, trailing;
};
Voltages probe_voltages(std::size_t n, std::int64_t delay, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<double> level(n + static_cast<std::size_t>(delay));
  bool air = false;
  std::size_t next = 0;
  for (std::size_t i = 0; i < level.size(); ++i) {
    if (i == next) {
      air = !air;
      next = i + 2 + rng() % (air ? 20 : 120);
    }
    level[i] = air ? 0.3 : 4.1;
  }
  Voltages v;
  for (std::size_t i = 0; i < n; ++i) {
    v.leading.push_back(level[i + static_cast<std::size_t>(delay)] + noise(rng));
    v.trailing.push_back(level[i] + noise(rng));
  }
  return v;
}

void feed_in_blocks(awcc::LaggedPearson& p, const std::vector<double>& x, const std::vector<double>& y, std::size_t block) {
  for (std::size_t i = 0; i < x.size(); i += block) {
    const std::size_t len = std::min(block, x.size() - i);
    p.feed(static_cast<std::int64_t>(i), std::span<const double>(x.data() + i, len), std::span<const double>(y.data() + i, len));
  }
}

TEST(LaggedPearson, EqualsANaiveLongDoubleSumWhateverTheBlocks) {
  const auto v = probe_voltages(20'000, 7, 3);
  // Windows shorter and longer than one FFT chunk, lags on both sides of 0.
  for (auto [start, window, k0, k1] : {std::tuple<std::int64_t, std::int64_t, std::int64_t, std::int64_t>{199, 15'000, -199, 800},
                                       {0, 19'000, 0, 999},
                                       {5'000, 300, -50, 60},
                                       {100, 19'800, -100, 99}}) {
    const auto naive = awcc::lagged_pearson_naive(v.leading, v.trailing, start, window, k0, k1);
    for (std::size_t block : {std::size_t{1} << 16, std::size_t{997}, std::size_t{1}}) {
      if (block == 1 && window > 1000) continue;  // sample by sample: a short window suffices
      awcc::FftPlanCache plans;
      awcc::LaggedPearson p(start, window, k0, k1, plans);
      feed_in_blocks(p, v.leading, v.trailing, block);
      ASSERT_TRUE(p.complete());
      const auto fast = p.coefficients();
      ASSERT_EQ(fast.size(), naive.size());
      for (std::size_t j = 0; j < fast.size(); ++j) {
        ASSERT_NEAR(fast[j], naive[j], 1e-12) << "lag " << k0 + static_cast<std::int64_t>(j) << " block " << block;
      }
    }
  }
}

TEST(LaggedPearson, AnAutoCorrelationReadsXFromY) {
  // same_signal: X is taken from y's samples and its sums from y's prefix sums.
  const auto v = probe_voltages(20'000, 0, 5);
  for (auto [start, window, k0, k1] : {std::tuple<std::int64_t, std::int64_t, std::int64_t, std::int64_t>{0, 19'000, 0, 999},
                                       {300, 15'000, -199, 800}}) {
    const auto naive = awcc::lagged_pearson_naive(v.leading, v.leading, start, window, k0, k1);
    awcc::FftPlanCache plans;
    awcc::LaggedPearson p(start, window, k0, k1, plans, true);
    const std::vector<double> ignored(v.leading.size(), 99.0);  // x is not read
    feed_in_blocks(p, ignored, v.leading, 4096);
    ASSERT_TRUE(p.complete());
    const auto fast = p.coefficients();
    for (std::size_t j = 0; j < fast.size(); ++j) ASSERT_NEAR(fast[j], naive[j], 1e-12) << j;
    EXPECT_NEAR(fast[static_cast<std::size_t>(-k0)], 1.0, 1e-12);
  }
}

TEST(LaggedPearson, AConstantWindowHasNoCoefficient) {
  std::vector<double> x(2'000, 4.1), y(2'000);
  for (std::size_t i = 0; i < y.size(); ++i) y[i] = (i / 7) % 2 ? 0.3 : 4.1;
  awcc::FftPlanCache plans;
  awcc::LaggedPearson p(10, 1'000, -10, 10, plans);
  feed_in_blocks(p, x, y, 512);
  for (double r : p.coefficients()) EXPECT_TRUE(std::isnan(r));
}

TEST(LaggedPearson, RefusesSkippedSamples) {
  std::vector<double> x(100, 1.0);
  awcc::FftPlanCache plans;
  awcc::LaggedPearson p(0, 50, 0, 10, plans);
  p.feed(0, std::span<const double>(x.data(), 20), std::span<const double>(x.data(), 20));
  EXPECT_THROW(p.feed(30, std::span<const double>(x.data(), 20), std::span<const double>(x.data(), 20)),
               std::invalid_argument);
}

// Felder's segmented coefficient (felder-program.md 3), written out: in
// segment s of L = N div S samples (offset h), B = L - 1000, the auto
// coefficient at lag o over x[h .. h+B) and x[h+o ..), the cross coefficient
// at lag o - 199 over x[h+199 .. h+199+B) and y[h+o ..), both as
// (B sum XY - sum X sum Y) / sqrt((B sum X^2 - (sum X)^2)(B sum Y^2 - (sum Y)^2)),
// averaged over the S segments.
long double felder_coefficient(const std::vector<double>& x, const std::vector<double>& y, std::size_t x0, std::size_t y0,
                               std::size_t b) {
  long double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (std::size_t t = 0; t < b; ++t) {
    const long double a = x[x0 + t], c = y[y0 + t];
    sx += a;
    sy += c;
    sxx += a * a;
    syy += c * c;
    sxy += a * c;
  }
  const long double n = static_cast<long double>(b);
  return (n * sxy - sx * sy) / (std::sqrt(n * sxx - sx * sx) * std::sqrt(n * syy - sy * sy));
}

TEST(RawCorrelation, MatchesFeldersSegmentedPearsonAndRecoversTheDelay) {
  const std::size_t n = 45'000;
  const std::int64_t delay = 23;
  const auto v = probe_voltages(n, delay, 11);
  awcc::FsccOptions o;
  o.segments = 3;
  o.felder_lags = true;
  awcc::FftPlanCache plans;
  awcc::RawCorrelation raw(static_cast<std::int64_t>(n), 20e3, o, plans);
  for (std::size_t i = 0; i < n; i += 4096) {
    const std::size_t len = std::min<std::size_t>(4096, n - i);
    raw.feed(static_cast<std::int64_t>(i), std::span<const double>(v.leading.data() + i, len),
             std::span<const double>(v.trailing.data() + i, len));
  }
  auto f = raw.finish();
  ASSERT_EQ(f.status, awcc::FsccStatus::ok);
  ASSERT_EQ(f.r11.size(), 1000u);
  ASSERT_EQ(f.r12.size(), 1000u);
  const std::size_t length = n / 3, b = length - 1000;
  for (std::size_t o_lag : {0u, 1u, 57u, 199u, 222u, 999u}) {
    long double r11 = 0, r12 = 0;
    for (std::size_t s = 0; s < 3; ++s) {
      const std::size_t h = s * length;
      r11 += felder_coefficient(v.leading, v.leading, h, h + o_lag, b);
      r12 += felder_coefficient(v.leading, v.trailing, h + 199, h + o_lag, b);
    }
    EXPECT_NEAR(f.r11[o_lag], static_cast<double>(r11 / 3), 1e-12) << o_lag;
    EXPECT_NEAR(f.r12[o_lag], static_cast<double>(r12 / 3), 1e-12) << o_lag;
  }
  const auto result = awcc::fscc_from_functions(std::move(f), 5e-3, o);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_EQ(result.lag_samples, delay);
  EXPECT_EQ(result.signal, awcc::CorrelationSignal::raw);
  EXPECT_EQ(result.segments_used, 3);
}

TEST(RawCorrelation, SaysWhichTipIsConstant) {
  const std::size_t n = 12'000;
  const auto v = probe_voltages(n, 5, 2);
  const std::vector<double> flat(n, 4.1);
  awcc::FsccOptions o;
  o.max_lag = 0.005;
  awcc::FftPlanCache plans;
  for (bool leading_flat : {true, false}) {
    awcc::RawCorrelation raw(static_cast<std::int64_t>(n), 20e3, o, plans);
    raw.feed(0, leading_flat ? flat : v.leading, leading_flat ? v.trailing : flat);
    const auto f = raw.finish();
    EXPECT_EQ(f.status, leading_flat ? awcc::FsccStatus::constant_leading : awcc::FsccStatus::constant_trailing);
    EXPECT_FALSE(f.message.empty());
  }
}

// The scales of hand-made functions: interpolated crossings, a scale not
// reached is empty with a reason, and Felder's one-lag-past integrals.
awcc::CorrelationFunctions made(std::vector<double> r11, std::vector<double> r12, std::int64_t r12_first) {
  awcc::CorrelationFunctions f;
  f.fs = 1000.0;
  f.r11 = std::move(r11);
  f.r12 = std::move(r12);
  f.r12_first_lag = r12_first;
  f.segments_used = 1;
  return f;
}

TEST(FsccScales, CrossingsAreInterpolatedAndTheHalfWidthIsRightOfThePeak) {
  // R11: 1, 0.8, 0.4, -0.2, -0.1: T05 between lags 1 and 2 at 1 + (0.5 - 0.8) / (0.4 - 0.8) = 1.75;
  // zero between 2 and 3 at 2 + 0.4 / 0.6 = 2.6667; Txx = (1 + 0.8) / 2 + (0.8 + 0.4) / 2 + 0.4 * (2/3) / 2.
  // R12 at lags -1..4: 0.1, 0.3, 0.6, 0.45, 0.2, -0.1: peak at lag 1; half (0.3) between lags 2 and 3
  // at 2 + (0.3 - 0.45) / (0.2 - 0.45) = 2.6; tau05 = 1.6 lags; zero at 3 + 0.2 / 0.3.
  const auto r = awcc::fscc_from_functions(made({1, 0.8, 0.4, -0.2, -0.1}, {0.1, 0.3, 0.6, 0.45, 0.2, -0.1}, -1), 1.0, {});
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.lag_samples, 1);
  EXPECT_NEAR(*r.t05, 1.75e-3, 1e-15);
  EXPECT_NEAR(*r.t_r11_zero, (2.0 + 0.4 / 0.6) * 1e-3, 1e-15);
  EXPECT_EQ(*r.r11_min, 0.0);
  EXPECT_NEAR(*r.txx, (0.9 + 0.6 + 0.4 * (0.4 / 0.6) / 2) * 1e-3, 1e-15);
  EXPECT_NEAR(*r.t_half, 2.6e-3, 1e-15);
  EXPECT_NEAR(*r.tau05, 1.6e-3, 1e-15);
  EXPECT_NEAR(*r.t_r12_zero, (3.0 + 0.2 / 0.3) * 1e-3, 1e-15);
  // Tu = 0.851 sqrt(tau05^2 - T05^2) / T: tau05 = 1.6 ms < T05 = 1.75 ms: undefined, and said.
  EXPECT_FALSE(r.turbulence_intensity_chanson);
  bool said = false;
  for (const auto& [name, why] : r.scale_notes) said = said || name == "turbulence_intensity_chanson";
  EXPECT_TRUE(said);
}

TEST(FsccScales, AScaleNotReachedIsEmptyWithItsReason) {
  const auto r = awcc::fscc_from_functions(made({1, 0.9, 0.7, 0.6}, {0.2, 0.5, 0.9, 0.8, 0.7, 0.6}, -1), 1.0, {});
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_FALSE(r.t05);
  EXPECT_FALSE(r.t_r11_zero);
  EXPECT_FALSE(r.txx);
  EXPECT_NEAR(*r.r11_min, 0.6, 1e-15);  // the minimum instead, and its lag
  EXPECT_NEAR(*r.t_r11_min, 3e-3, 1e-15);
  EXPECT_FALSE(r.tau05);
  EXPECT_FALSE(r.t_r12_zero);
  std::vector<std::string> names;
  for (const auto& [name, why] : r.scale_notes) {
    names.push_back(name);
    EXPECT_FALSE(why.empty());
  }
  for (const char* name : {"t05", "t_r11_zero", "txx", "tau05", "t_r12_zero", "txy"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  }
}

TEST(FsccScales, FeldersIntegralsRunOneLagPastTheZero) {
  // His Txx: trapezoids (R_i + R_{i+1}) / 2f for i up to and including the
  // first lag at or below 0: 0.9 + 0.6 + 0.1 + (-0.2 - 0.1) / 2 = 1.45 lags.
  awcc::FsccOptions o;
  o.felder_scales = true;
  const auto r = awcc::fscc_from_functions(made({1, 0.8, 0.4, -0.2, -0.1}, {0.1, 0.3, 0.6, 0.45, 0.2, -0.1}, -1), 1.0, o);
  EXPECT_NEAR(*r.txx, 1.45e-3, 1e-15);
  // Txy from the peak (lag 1): (0.6 + 0.45) / 2 + (0.45 + 0.2) / 2 + (0.2 - 0.1) / 2, then the last lag alone: -0.1.
  EXPECT_NEAR(*r.txy, (0.525 + 0.325 + 0.05 - 0.1) * 1e-3, 1e-15);
}

}  // namespace
