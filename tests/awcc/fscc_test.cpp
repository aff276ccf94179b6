#include "awcc/detail/fscc_steps.hpp"
#include "awcc/fscc.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "random_signals.hpp"

namespace {

using awcc::AirIntervals;

// Chords of 2..11 (air) and 2..41 (water) samples.
AirIntervals telegraph(std::int64_t n, unsigned seed, double fs = 1000.0) {
  return pdp_test::telegraph(n, seed, fs, 10, 40, 2);
}

AirIntervals shifted(const AirIntervals& s, std::int64_t delay) {
  auto dense = awcc::to_dense(s);
  std::vector<std::uint8_t> out(dense.size(), 0);
  for (std::size_t i = 0; i < dense.size(); ++i) {
    const auto j = static_cast<std::int64_t>(i) + delay;
    if (j >= 0 && j < static_cast<std::int64_t>(dense.size())) out[static_cast<std::size_t>(j)] = dense[i];
  }
  return awcc::from_dense(out, s.fs);
}

TEST(LaggedProducts, EqualANaiveLongDoubleSum) {
  const auto x = telegraph(50'000, 1), y = telegraph(50'000, 2);
  const auto dx = awcc::to_dense(x), dy = awcc::to_dense(y);
  awcc::FftPlanCache plans;
  for (auto [t0, t1, kmin, kmax] : {std::tuple<std::int64_t, std::int64_t, std::int64_t, std::int64_t>{0, 50'000, -300, 700},
                                    {1234, 40'000, 0, 999},
                                    {0, 50'000, -5, -1},
                                    {49'000, 50'000, 10, 2000}}) {
    const auto fast = awcc::detail::lagged_products(x, y, t0, t1, kmin, kmax, plans, awcc::detail::ProductPath::fft);
    const auto pairs = awcc::detail::lagged_products(x, y, t0, t1, kmin, kmax, plans, awcc::detail::ProductPath::intervals);
    ASSERT_EQ(fast.size(), static_cast<std::size_t>(kmax - kmin + 1));
    ASSERT_EQ(fast, pairs);
    for (std::int64_t k = kmin; k <= kmax; k += 7) {
      long double naive = 0;
      for (std::int64_t t = t0; t < t1; ++t) {
        const std::int64_t u = t + k;
        if (u >= 0 && u < 50'000) naive += static_cast<long double>(dx[static_cast<std::size_t>(t)]) * dy[static_cast<std::size_t>(u)];
      }
      ASSERT_EQ(fast[static_cast<std::size_t>(k - kmin)], static_cast<double>(naive)) << "k " << k << " t0 " << t0;
    }
  }
}

TEST(Fscc, NormalisedCorrelationMatchesTheDefinition) {
  const auto x = telegraph(20'000, 5), y = shifted(x, 17);
  awcc::FsccOptions o;
  o.max_lag = 0.05;  // 50 samples at 1 kHz
  const auto r = awcc::fscc(x, y, 1.0, o);
  const auto dx = awcc::to_dense(x), dy = awcc::to_dense(y);
  long double mx = 0, my = 0;
  for (std::size_t i = 0; i < dx.size(); ++i) {
    mx += dx[i];
    my += dy[i];
  }
  mx /= dx.size();
  my /= dy.size();
  long double qx = 0, qy = 0;
  for (std::size_t i = 0; i < dx.size(); ++i) {
    qx += (dx[i] - mx) * (dx[i] - mx);
    qy += (dy[i] - my) * (dy[i] - my);
  }
  for (std::int64_t k = -50; k <= 50; k += 5) {
    long double s = 0;
    for (std::int64_t t = 0; t < 20'000; ++t) {
      const std::int64_t u = t + k;
      if (u < 0 || u >= 20'000) continue;
      s += (dx[static_cast<std::size_t>(t)] - mx) * (dy[static_cast<std::size_t>(u)] - my);
    }
    EXPECT_NEAR(r.r12[static_cast<std::size_t>(k - r.r12_first_lag)], static_cast<double>(s / std::sqrt(qx * qy)), 1e-12)
        << k;
  }
}

TEST(Fscc, RecoversAPlantedDelayExactly) {
  for (std::int64_t delay : {1, 17, 250}) {
    const auto x = telegraph(100'000, 7, 500e3);
    const auto y = shifted(x, delay);
    awcc::FsccOptions o;
    o.max_lag = 1e-3;  // 500 samples
    const auto r = awcc::fscc(x, y, 5e-3, o);
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_EQ(r.lag_samples, delay);
    EXPECT_NEAR(r.velocity, 5e-3 / (static_cast<double>(delay) / 500e3), 1e-9);
    EXPECT_GT(r.r12_max, 0.99);
    ASSERT_TRUE(r.t05.has_value());
    ASSERT_TRUE(r.tau05.has_value());
    // A pure shift: R12 is R11 moved by the delay, so tau05 = T05 (half-width).
    EXPECT_NEAR(*r.tau05, *r.t05, 1.0 / 500e3);
  }
}

TEST(Fscc, ParabolicRefinementFindsAFractionalDelay) {
  // y = average of x delayed by 20 and 21 samples (soft 0/0.5/1 is not
  // binary, so build it at 10x the rate and decimate): the true delay is
  // 20.5 samples; the integer peak is 20 or 21, the parabola lands near 20.5.
  const auto fine = telegraph(400'000, 11, 10.0);
  const auto y_fine = shifted(fine, 205);
  auto decimate = [](const AirIntervals& s) {
    const auto d = awcc::to_dense(s);
    std::vector<std::uint8_t> out;
    for (std::size_t i = 0; i < d.size(); i += 10) out.push_back(d[i]);
    return awcc::from_dense(out, 1.0);
  };
  const auto x = decimate(fine), y = decimate(y_fine);
  awcc::FsccOptions o;
  o.max_lag = 100;
  o.subsample = awcc::Subsample::parabolic;
  const auto r = awcc::fscc(x, y, 1.0, o);
  EXPECT_NEAR(r.lag, 20.5, 0.2);
  o.subsample = awcc::Subsample::none;
  const auto integer = awcc::fscc(x, y, 1.0, o);
  EXPECT_EQ(integer.lag, static_cast<double>(integer.lag_samples));
}

TEST(Fscc, SegmentedMatchesNaivePearsonAverages) {
  const auto x = telegraph(30'000, 21), y = shifted(x, 9);
  awcc::FsccOptions o;
  o.segments = 3;
  o.felder_lags = true;
  const auto r = awcc::fscc(x, y, 1.0, o);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.lag_samples, 9);
  const auto dx = awcc::to_dense(x), dy = awcc::to_dense(y);
  const std::int64_t length = 10'000;
  for (std::int64_t k : {-199, -50, 0, 9, 300, 800}) {
    long double acc = 0;
    for (int s = 0; s < 3; ++s) {
      // Felder's window: B = L - 1000 samples from the segment's start + 199.
      const std::int64_t t0 = s * length + 199, t1 = t0 + length - 1000;
      long double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
      const long double w = static_cast<long double>(t1 - t0);
      for (std::int64_t t = t0; t < t1; ++t) {
        const long double a = dx[static_cast<std::size_t>(t)], b = dy[static_cast<std::size_t>(t + k)];
        sx += a; sy += b; sxx += a * a; syy += b * b; sxy += a * b;
      }
      acc += (sxy / w - sx / w * sy / w) / std::sqrt((sxx / w - sx * sx / (w * w)) * (syy / w - sy * sy / (w * w)));
    }
    EXPECT_NEAR(r.r12[static_cast<std::size_t>(k + 199)], static_cast<double>(acc / 3), 1e-12) << k;
  }
}

// fscc() builds the full record's R12 from the interval's segment windows
// and the gaps between them; it must equal, bit for bit, the functions
// computed over the whole record at once (correlation_functions), and its
// interval those of the segments computed on their own. The 1,000-sample
// record has segment lags narrower than the record's (limit L / 4 = 25), so
// fscc() takes its plain path there: the same comparison covers it.
TEST(Fscc, FullRecordFromSegmentWindowsEqualsTheWholeRecordsProducts) {
  for (const std::int64_t n : {100'000, 1'000}) {
    const auto x = telegraph(n, 31), y = shifted(telegraph(n, 31), 12);
    awcc::FsccOptions o;
    o.max_lag = 0.05;  // 50 samples at 1 kHz
    const auto r = awcc::fscc(x, y, 1.0, o);
    auto expected = awcc::fscc_from_functions(awcc::correlation_functions(x, y, o), 1.0, o);
    ASSERT_TRUE(r.ok()) << r.message;
    ASSERT_TRUE(expected.ok());
    awcc::add_velocity_interval(expected, awcc::correlation_functions(x, y, awcc::interval_options(o)), 1.0);
    EXPECT_EQ(r.r11, expected.r11) << n;
    EXPECT_EQ(r.r12, expected.r12) << n;
    EXPECT_EQ(r.interval_segments, expected.interval_segments) << n;
    ASSERT_EQ(r.velocity_ci95.has_value(), expected.velocity_ci95.has_value()) << n;
    if (r.velocity_ci95) {
      EXPECT_EQ(r.velocity_ci95->lower, expected.velocity_ci95->lower);
      EXPECT_EQ(r.velocity_ci95->upper, expected.velocity_ci95->upper);
    }
  }
}

// The auto-correlation summed on a thread of its own (what pdp process does
// with a second core) against the one-thread run: sums of whole numbers, so
// every output equals bit for bit. Records long and short (the shortest does
// not partition into the segments' windows, and the thread's sums are then
// computed and not used), with chords of tens of samples and of one to three.
TEST(Fscc, AutoCorrelationOnASecondThreadGivesTheSameBits) {
  struct Case {
    std::int64_t n;
    int max_air, max_water, min_length;
  };
  unsigned seed = 40;
  for (const Case c : {Case{200'000, 10, 40, 2}, Case{200'000, 3, 3, 1}, Case{1'000, 10, 40, 2}, Case{60, 3, 3, 1}}) {
    const auto x = pdp_test::telegraph(c.n, ++seed, 1000.0, c.max_air, c.max_water, c.min_length);
    const auto y = shifted(x, 3);
    awcc::FsccOptions o;
    o.max_lag = 0.05;
    const auto one = awcc::fscc(x, y, 1.0, o, false);
    const auto two = awcc::fscc(x, y, 1.0, o, true);
    EXPECT_EQ(one.status, two.status) << c.n;
    EXPECT_EQ(one.r11, two.r11) << c.n;
    EXPECT_EQ(one.r12, two.r12) << c.n;
    EXPECT_EQ(one.velocity, two.velocity) << c.n;
    EXPECT_EQ(one.t05, two.t05) << c.n;
    EXPECT_EQ(one.txx, two.txx) << c.n;
    ASSERT_EQ(one.velocity_ci95.has_value(), two.velocity_ci95.has_value()) << c.n;
    if (one.velocity_ci95) {
      EXPECT_EQ(one.velocity_ci95->lower, two.velocity_ci95->lower) << c.n;
    }
    // And against the whole record's functions, computed apart.
    if (one.ok()) {
      EXPECT_EQ(two.r11, awcc::correlation_functions(x, y, o).r11) << c.n;
    }
  }
}

TEST(Fscc, UndefinedResultsCarryAReason) {
  const auto x = telegraph(10'000, 3);
  AirIntervals empty;
  empty.fs = x.fs;
  empty.sample_count = x.sample_count;
  const auto none = awcc::fscc(x, empty, 1.0, {});
  EXPECT_FALSE(none.ok());
  EXPECT_NE(none.message.find("constant"), std::string::npos);
  const auto backwards = awcc::fscc(shifted(x, 5), x, 1.0, {});
  EXPECT_FALSE(backwards.ok());
  EXPECT_NE(backwards.message.find("not positive"), std::string::npos);
  EXPECT_EQ(backwards.lag_samples, -5);
}

TEST(FftSize, IsSmoothAndLargeEnough) {
  for (std::size_t n : {1u, 17u, 1000u, 65537u, 1234567u}) {
    const auto m = awcc::fast_fft_size(n);
    EXPECT_GE(m, n);
    auto r = m;
    while (r % 2 == 0) r /= 2;
    EXPECT_TRUE(r == 1 || r == 3 || r == 5) << m;
    EXPECT_LE(m, 2 * n);
  }
}

}  // namespace
