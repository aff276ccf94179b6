// The velocity series (awcc/velocity_series.hpp): sample-and-hold, Welch's
// PSD, the autocorrelation and its integral time scale, against exact values
// and sampling-theory bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>

#include "awcc/velocity_series.hpp"

namespace {

TEST(SampleAndHold, EachPointTakesTheLatestValue) {
  const std::vector<double> t{0.10, 0.25, 0.40}, v{1.0, 2.0, 3.0};
  const auto s = awcc::sample_and_hold(t, v, 10.0, 0.1, 0.5);  // points at 0.1, 0.2, ..., 0.5
  EXPECT_EQ(s.values, (std::vector<double>{1.0, 1.0, 2.0, 3.0, 3.0}));
  EXPECT_EQ(s.rate, 10.0);
}

TEST(WelchPsd, ASinusoidPeaksAtItsFrequencyAndTheSpectrumHoldsTheVariance) {
  // A = 2 at 12.5 Hz (a bin centre of 256-point segments at 200 Hz), plus
  // white noise of sd 0.5. Parseval: the integral of the one-sided PSD is the
  // variance, A^2 / 2 + 0.25 = 2.25; Welch with Hann windows keeps it to the
  // sampling error of the noise part (below 1 % here: 780 segments).
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.5);
  const double rate = 200.0;
  std::vector<double> x(100'000);
  for (std::size_t i = 0; i < x.size(); ++i)
    x[i] = 2.0 * std::sin(2 * std::numbers::pi * 12.5 * static_cast<double>(i) / rate) + noise(rng);
  const auto p = awcc::welch_psd(x, rate, 256);
  ASSERT_EQ(p.frequency.size(), 129u);
  EXPECT_EQ(p.segments, 780);
  double integral = 0.0;
  for (double d : p.density) integral += d * rate / 256.0;
  EXPECT_NEAR(integral, 2.25, 0.03);
  const auto peak = std::max_element(p.density.begin(), p.density.end()) - p.density.begin();
  EXPECT_DOUBLE_EQ(p.frequency[static_cast<std::size_t>(peak)], 12.5);
  // Away from the peak the density is the noise's, 2 sigma^2 / rate = 0.0025 per Hz;
  // the mean over 80 bins of 780 averaged segments has a relative sd of about
  // 1 / sqrt(780 x 80 / 2) = 0.6 %: 5 % holds with a wide margin.
  double far = 0.0;
  for (std::size_t k = 40; k < 120; ++k) far += p.density[k];
  EXPECT_NEAR(far / 80.0, 0.0025, 0.0025 * 0.05);
}

TEST(Autocorrelation, EqualsTheDirectSumAndRecoversAnAr1TimeScale) {
  // AR(1) x_{k+1} = phi x_k + e: r(k) = phi^k; the trapezoid integral to the
  // first zero is dt (1 / (1 - phi) - 1/2) = 9.5 dt for phi = 0.9, less the
  // tail beyond the zero crossing (~ lag 45 where r ~ its sd, sqrt(9.5 / N)
  // ~ 0.007: phi^45 / (1 - phi) = 0.09 dt). The integral's sampling sd is
  // about dt (lags to the zero) x sd(r) ~ 45 x 0.007 dt = 0.3 dt: 1.5 dt
  // (5 sd) bounds the estimate around 9.4 dt.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> e(0.0, 1.0);
  std::vector<double> x(200'000);
  for (std::size_t i = 1; i < x.size(); ++i) x[i] = 0.9 * x[i - 1] + e(rng);
  const auto r = awcc::autocorrelation(x, 200);
  ASSERT_EQ(r.size(), 201u);
  EXPECT_DOUBLE_EQ(r[0], 1.0);
  // The FFT path against the direct biased sum at a few lags.
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  long double q = 0;
  for (double v : x) q += (v - mean) * (v - mean);
  for (std::size_t k : {1u, 7u, 50u, 200u}) {
    long double s = 0;
    for (std::size_t i = 0; i + k < x.size(); ++i) s += (x[i] - mean) * (x[i + k] - mean);
    EXPECT_NEAR(r[k], static_cast<double>(s / q), 1e-12) << k;
  }
  EXPECT_NEAR(r[1], 0.9, 0.01);
  const auto t = awcc::integral_to_first_zero(r, 0.01);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 0.094, 0.015);
  EXPECT_FALSE(awcc::integral_to_first_zero(std::vector<double>{1.0, 0.8, 0.5}, 1.0));
  EXPECT_NEAR(*awcc::integral_to_first_zero(std::vector<double>{1.0, 0.5, -0.5}, 1.0), 0.75 + 0.125, 1e-15);
}

TEST(Autocorrelation, SlottingRecoversTheTimeScaleThatHoldingBiases) {
  // An Ornstein-Uhlenbeck velocity of scale T = 50 ms observed at Poisson
  // instants of rate nu = 20/s for 2000 s (exact updates between instants).
  // Slotted (slots of 10 ms): the integral to the first zero estimates T; its
  // sampling sd is about sqrt(2 T_0 / D) ~ sqrt(0.4 / 2000) = 1.4 % (zero
  // crossing T_0 ~ 4 T), the trapezoids of 10 ms add under 1 %: 6 % bounds it.
  // Sample-and-hold at 100 Hz: the held series' autocorrelation is
  // e^{-nu tau} + (1 - e^{-nu tau}) e^{-tau/T}, integral T + 1/nu - T/(1 + nu T)
  // = 75 ms (velocity_series.hpp), which the held estimate meets within 6 %.
  std::mt19937_64 rng(9);
  std::exponential_distribution<double> gap(20.0);
  std::normal_distribution<double> e(0.0, 1.0);
  const double t_scale = 0.05;
  std::vector<double> times, values;
  double t = 0.0, u = 0.0;
  while (t < 2000.0) {
    const double dt = gap(rng);
    t += dt;
    const double a = std::exp(-dt / t_scale);
    u = a * u + std::sqrt(1.0 - a * a) * e(rng);
    times.push_back(t);
    values.push_back(3.0 + 0.5 * u);
  }
  const auto r = awcc::slotted_autocorrelation(times, values, 0.01, 100);
  const auto slotted = awcc::integral_to_first_zero(r, 0.01);
  ASSERT_TRUE(slotted);
  EXPECT_NEAR(*slotted, t_scale, 0.06 * t_scale);
  const auto held = awcc::sample_and_hold(times, values, 100.0, times.front(), times.back());
  const auto held_scale = awcc::integral_to_first_zero(awcc::autocorrelation(held.values, 2000), 0.01);
  ASSERT_TRUE(held_scale);
  const double expected = t_scale + 1.0 / 20.0 - t_scale / (1.0 + 20.0 * t_scale);
  EXPECT_NEAR(*held_scale, expected, 0.06 * expected);
}

TEST(VelocitySpectrum, NeedsAnAwccSeriesLongerThanASegment) {
  awcc::AwccResult none;
  EXPECT_EQ(awcc::velocity_spectrum(none, 10.0, {}).status, awcc::SpectrumStatus::no_awcc_velocity);
  awcc::AwccResult few;
  few.status = awcc::AwccStatus::ok;
  for (int i = 0; i < 50; ++i) {
    awcc::AwccWindow w;
    w.start_time = 0.01 * i;
    w.duration = 0.01;
    w.velocity = 3.0 + 0.1 * (i % 3);
    few.windows.push_back(w);
  }
  const auto s = awcc::velocity_spectrum(few, 0.5, {});
  EXPECT_EQ(s.status, awcc::SpectrumStatus::too_few_points);
  EXPECT_NE(s.message.find("segment"), std::string::npos);
  awcc::SpectrumOptions shorter;
  shorter.segment_length = 16;
  const auto ok = awcc::velocity_spectrum(few, 0.5, shorter);
  EXPECT_EQ(ok.status, awcc::SpectrumStatus::ok);
  EXPECT_NEAR(ok.resample_rate, 100.0, 1e-9);
  EXPECT_NEAR(ok.resolvable_frequency, 50.0, 1e-9);
}

// An Ornstein-Uhlenbeck velocity of scale t_scale at Poisson instants of
// rate nu over `duration` s (exact updates between instants).
struct IrregularSeries {
  std::vector<double> times, values;
};
IrregularSeries ou_at_poisson_instants(double t_scale, double nu, double duration, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::exponential_distribution<double> gap(nu);
  std::normal_distribution<double> e(0.0, 1.0);
  IrregularSeries s;
  double t = 0.0, u = 0.0;
  while (t < duration) {
    const double dt = gap(rng);
    t += dt;
    const double a = std::exp(-dt / t_scale);
    u = a * u + std::sqrt(1.0 - a * a) * e(rng);
    s.times.push_back(t);
    s.values.push_back(3.0 + 0.5 * u);
  }
  return s;
}

TEST(SlottedIntegral, EqualsTheIntegralOfTheWholeSlottedAutocorrelationBitForBit) {
  // Band by band or all slots at once, each slot's sum takes the same pairs
  // in the same order: the same doubles. Scales from a fraction of a slot
  // (zero in the first band) to beyond every slot (no zero: the integral so
  // far), and slot counts that end inside a band and on its edge.
  int reached = 0, not_reached = 0;
  for (const double t_scale : {0.002, 0.05, 0.4, 30.0}) {
    const auto s = ou_at_poisson_instants(t_scale, 20.0, 400.0, 11);
    for (const std::size_t slots : {1u, 16u, 17u, 100u, 1000u}) {
      const double slot = 0.01;
      const auto r = awcc::slotted_autocorrelation(s.times, s.values, slot, slots);
      const auto whole = awcc::integral_to_first_zero(r, slot);
      const auto banded = awcc::slotted_integral_to_first_zero(s.times, s.values, slot, slots,
                                                               std::numeric_limits<double>::infinity());
      EXPECT_FALSE(banded.stopped);
      ASSERT_EQ(banded.zero_reached, whole.has_value()) << t_scale << " " << slots;
      if (whole) {
        EXPECT_EQ(banded.integral, *whole) << t_scale << " " << slots;
        ++reached;
      } else {
        // The trapezoids over every slot, as integral_to_first_zero sums them.
        double area = 0.0;
        for (std::size_t i = 0; i < slots; ++i) area += 0.5 * (r[i] + r[i + 1]);
        EXPECT_EQ(banded.integral, area * slot) << t_scale << " " << slots;
        ++not_reached;
      }
    }
  }
  EXPECT_GT(reached, 5);
  EXPECT_GT(not_reached, 3);
}

TEST(SlottedIntegral, StopsAtTheFirstTrapezoidThatReachesTheLimit) {
  const auto s = ou_at_poisson_instants(0.3, 20.0, 400.0, 12);
  const double slot = 0.01;
  const std::size_t slots = 1000;
  const auto r = awcc::slotted_autocorrelation(s.times, s.values, slot, slots);
  const auto whole = awcc::integral_to_first_zero(r, slot);
  ASSERT_TRUE(whole);
  ASSERT_GT(*whole, 0.2);
  // The partial integral after each trapezoid, from the whole r.
  std::vector<double> partial{0.0};
  for (std::size_t i = 0; r[i + 1] > 0.0; ++i) partial.push_back(partial.back() + 0.5 * (r[i] + r[i + 1]));
  const std::size_t m = partial.size() / 2;
  const double limit = partial[m] * slot;
  // At the limit (the trapezoid that reaches it exactly) and just above it.
  const auto at = awcc::slotted_integral_to_first_zero(s.times, s.values, slot, slots, limit);
  EXPECT_TRUE(at.stopped);
  EXPECT_EQ(at.integral, limit);
  const auto above = awcc::slotted_integral_to_first_zero(s.times, s.values, slot, slots, std::nextafter(limit, 1.0));
  EXPECT_TRUE(above.stopped);
  EXPECT_EQ(above.integral, partial[m + 1] * slot);
  // A limit beyond the whole integral: the zero first.
  const auto beyond = awcc::slotted_integral_to_first_zero(s.times, s.values, slot, slots, *whole * 1.01);
  EXPECT_FALSE(beyond.stopped);
  EXPECT_TRUE(beyond.zero_reached);
  EXPECT_EQ(beyond.integral, *whole);
}

// An AWCC result whose accepted windows are the series' points (each a
// window of duration t_w centred there); every fourth window rejected.
awcc::AwccResult windows_of(const IrregularSeries& s, double t_w) {
  awcc::AwccResult a;
  a.status = awcc::AwccStatus::ok;
  for (std::size_t i = 0; i < s.times.size(); ++i) {
    awcc::AwccWindow w;
    w.start_time = s.times[i] - 0.5 * t_w;
    w.duration = t_w;
    w.velocity = s.values[i];
    if (i % 4 == 3) w.fate = awcc::WindowFate::correlation;
    a.windows.push_back(w);
  }
  return a;
}

TEST(CappedTimeScaleRatio, IsTheSpectrumsRatioBelowTheCapAndTheCapAtOrAboveIt) {
  const auto s = ou_at_poisson_instants(0.1, 40.0, 300.0, 13);
  const auto a = windows_of(s, 0.02);
  awcc::SpectrumOptions o;
  o.segment_length = 64;
  const auto spectrum = awcc::velocity_spectrum(a, 300.0, o);
  ASSERT_EQ(spectrum.status, awcc::SpectrumStatus::ok);
  ASSERT_TRUE(spectrum.time_scale_ratio);
  const double ratio = *spectrum.time_scale_ratio;
  // T_u about 0.1 s over T_W = 0.02 s: about 5 (the slotted estimate's
  // sampling error at D = 300 s is a few percent).
  EXPECT_NEAR(ratio, 5.0, 1.0);
  EXPECT_EQ(awcc::capped_time_scale_ratio(a, 1e9), ratio);
  EXPECT_EQ(awcc::capped_time_scale_ratio(a, std::nextafter(ratio, 1e9)), ratio);
  EXPECT_EQ(awcc::capped_time_scale_ratio(a, ratio), ratio);
  EXPECT_EQ(awcc::capped_time_scale_ratio(a, std::nextafter(ratio, 0.0)), std::nextafter(ratio, 0.0));
  EXPECT_EQ(awcc::capped_time_scale_ratio(a, 2.0), 2.0);
}

TEST(CappedTimeScaleRatio, NeedsTwoAcceptedWindowsOfAnAwccVelocity) {
  awcc::AwccResult failed;
  EXPECT_FALSE(awcc::capped_time_scale_ratio(failed, 20.0));
  IrregularSeries two{{1.0, 1.5}, {3.0, 3.2}};
  auto a = windows_of(two, 0.1);
  EXPECT_TRUE(awcc::capped_time_scale_ratio(a, 20.0));
  a.windows[1].fate = awcc::WindowFate::correlation;
  EXPECT_FALSE(awcc::capped_time_scale_ratio(a, 20.0));
  EXPECT_FALSE(awcc::capped_time_scale_ratio(windows_of(two, 0.1), 0.0));
  // Every window at one velocity (one lag): no variance, r = 1 throughout: the cap.
  IrregularSeries flat;
  for (int i = 0; i < 200; ++i) {
    flat.times.push_back(0.1 * i);
    flat.values.push_back(4.0);
  }
  EXPECT_EQ(awcc::capped_time_scale_ratio(windows_of(flat, 0.1), 20.0), 20.0);
}

}  // namespace
