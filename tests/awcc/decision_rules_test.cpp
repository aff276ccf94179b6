// Decision rules at and around their limits: the AWCC correlation filter, the
// secondary peaks kept for the SPR, the velocity range of the lags searched,
// windows too short for that range, and binarisation (fixed threshold,
// Felder's tolerance, hysteresis) for conductivity and optical probes.
#include "awcc/detail/awcc_steps.hpp"
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "awcc/awcc.hpp"
#include "awcc/binarisation.hpp"
#include "random_signals.hpp"
#include "signal_builders.hpp"

namespace {

using awcc::WindowFate;

constexpr double inf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------
// AWCC correlation filter: reject a window when R12max / (SPR^2 + 1) < A.

// The fate of a window whose peak is at lag 15 samples (fs 1 kHz, dx 1 m)
// with the given height and SPR, under filter threshold A.
awcc::AwccWindow judged(double height, double spr, double a) {
  awcc::AwccWindow w;
  w.length = 1000;
  awcc::detail::CorrelationPeak p;
  p.index = 15;
  p.refined_index = 15.0;
  p.height = height;
  p.spr = spr;
  awcc::AwccOptions o;
  o.filter_a = a;
  awcc::detail::analyse_window(w, p, false, 0, 1.0, 1000.0, o);
  return w;
}

TEST(CorrelationFilter, RatioExactlyAtAIsAcceptedJustBelowIsRejected) {
  // R12max = 0.5, SPR = 0.5: SPR^2 + 1 = 1.25 exactly, and 0.5 / 1.25 is the
  // correctly rounded quotient 0.4, i.e. the double 0.4 = the default A.
  const double a = awcc::AwccOptions{}.filter_a;
  ASSERT_EQ(a, 0.4);
  ASSERT_EQ(0.5 / (0.5 * 0.5 + 1.0), a);
  const auto at = judged(0.5, 0.5, a);
  EXPECT_EQ(at.fate, WindowFate::accepted);  // the rule is "< A": equality passes
  EXPECT_EQ(at.r12_max, 0.5);
  EXPECT_EQ(at.spr, 0.5);
  EXPECT_EQ(at.lag_samples, 15);
  EXPECT_DOUBLE_EQ(at.velocity, 1.0 / 0.015);
  // The same window against A one ulp either side of the ratio.
  EXPECT_EQ(judged(0.5, 0.5, std::nextafter(a, 1.0)).fate, WindowFate::correlation);
  EXPECT_EQ(judged(0.5, 0.5, std::nextafter(a, 0.0)).fate, WindowFate::accepted);
  // A rejected window keeps its velocity (it is reported in the window table).
  EXPECT_DOUBLE_EQ(judged(0.5, 0.5, std::nextafter(a, 1.0)).velocity, 1.0 / 0.015);
}

TEST(CorrelationFilter, SinglePeakIsJudgedOnItsHeightAlone) {
  // SPR = 0: the ratio is R12max itself.
  const double a = 0.4;
  EXPECT_EQ(judged(a, 0.0, a).fate, WindowFate::accepted);
  EXPECT_EQ(judged(std::nextafter(a, 0.0), 0.0, a).fate, WindowFate::correlation);
  EXPECT_EQ(judged(std::nextafter(a, 1.0), 0.0, a).fate, WindowFate::accepted);
  // A = 0 accepts every positive-lag window, A = 1 only a perfect single peak.
  EXPECT_EQ(judged(1e-9, 0.9, 0.0).fate, WindowFate::accepted);
  EXPECT_EQ(judged(1.0, 0.0, 1.0).fate, WindowFate::accepted);
  EXPECT_EQ(judged(std::nextafter(1.0, 0.0), 0.0, 1.0).fate, WindowFate::correlation);
}

TEST(CorrelationFilter, SecondaryPeakOfAHandBuiltCorrelationMovesTheWindowAcrossA) {
  // R12 over lags -10..30: zero but for a spike of 0.5 at lag 15 (the peak)
  // and one of `second` at lag -2. Both spikes stand on a zero floor, so
  // their prominences are their heights; with second = 0.25 the secondary
  // peak is kept (0.25 >= 0.3 x 0.5) and SPR = 0.25 / 0.5 = 0.5 exactly:
  // ratio 0.5 / 1.25 = 0.4 = A.
  auto window = [](double second, double a) {
    std::vector<double> r(41, 0.0);
    r[25] = 0.5;
    r[8] = second;
    awcc::AwccOptions o;
    o.filter_a = a;
    awcc::AwccWindow w;
    w.length = 1000;
    awcc::AwccWorkspace workspace;
    awcc::detail::analyse_window(w, r, -10, 1.0, 1000.0, o, workspace);
    return w;
  };
  const auto at = window(0.25, 0.4);
  EXPECT_EQ(at.spr, 0.5);
  EXPECT_EQ(at.lag_samples, 15);
  EXPECT_EQ(at.fate, WindowFate::accepted);
  EXPECT_EQ(window(0.25, std::nextafter(0.4, 1.0)).fate, WindowFate::correlation);
  EXPECT_EQ(window(0.25, std::nextafter(0.4, 0.0)).fate, WindowFate::accepted);
  // A taller secondary peak raises the SPR and lowers the ratio below A;
  // a lower one does the opposite.
  const auto taller = window(0.25 + 1e-9, 0.4);
  EXPECT_GT(taller.spr, 0.5);
  EXPECT_EQ(taller.fate, WindowFate::correlation);
  const auto lower = window(0.25 - 1e-9, 0.4);
  EXPECT_LT(lower.spr, 0.5);
  EXPECT_EQ(lower.fate, WindowFate::accepted);
}

TEST(SecondaryPeakRatio, PeakOfProminenceExactlyTheFractionOfTheTallestIsKept) {
  // Spikes on a zero floor: the tallest 0.5 (prominence 0.5), a second one
  // of prominence `second`. Kept when second >= 0.3 x 0.5 = 0.15 (0.3 * 0.5
  // is exact halving of the double 0.3, which is the double 0.15).
  ASSERT_EQ(0.3 * 0.5, 0.15);
  auto spr = [](double second) {
    std::vector<double> r(30, 0.0);
    r[20] = 0.5;
    r[5] = second;
    awcc::AwccWorkspace workspace;
    return awcc::detail::analyse_correlation(r, awcc::Subsample::none, 0.3, workspace).spr;
  };
  EXPECT_EQ(spr(0.15), 0.15 / 0.5);  // at the limit: kept
  const double above = std::nextafter(0.15, 1.0);
  EXPECT_EQ(spr(above), above / 0.5);
  EXPECT_EQ(spr(std::nextafter(0.15, 0.0)), 0.0);  // just below: not kept, SPR 0
}

// ---------------------------------------------------------------------------
// Velocity range: lags searched k_min = floor(dx fs / u_max) to
// k_max = ceil(dx fs / u_min), within +/- min(length - 1, max_lag_samples).

awcc::AwccOptions velocity_range(double u_min, double u_max) {
  awcc::AwccOptions o;
  o.velocity_min = u_min;
  o.velocity_max = u_max;
  return o;
}

using LagRange = std::pair<std::int64_t, std::int64_t>;

TEST(VelocityRange, LagsSearchedByHand) {
  // dx 5 mm at 100 kHz: dx fs = 500 m/s x samples. 2-40 m/s: 500 / 40 = 12.5
  // -> 12; 500 / 2 = 250 -> 250.
  EXPECT_EQ(awcc::detail::awcc_lag_range(10'000, 5e-3, 100e3, velocity_range(2.0, 40.0)), (LagRange{12, 250}));
  // A window of 100 samples reaches lag 99 at most.
  EXPECT_EQ(awcc::detail::awcc_lag_range(100, 5e-3, 100e3, velocity_range(2.0, 40.0)), (LagRange{12, 99}));
  // No range: every lag of the window, or max_lag_samples when smaller.
  EXPECT_EQ(awcc::detail::awcc_lag_range(100, 5e-3, 100e3, {}), (LagRange{-99, 99}));
  awcc::AwccOptions capped;
  capped.max_lag_samples = 30;
  EXPECT_EQ(awcc::detail::awcc_lag_range(100, 5e-3, 100e3, capped), (LagRange{-30, 30}));
  capped = velocity_range(2.0, 40.0);
  capped.max_lag_samples = 30;
  EXPECT_EQ(awcc::detail::awcc_lag_range(10'000, 5e-3, 100e3, capped), (LagRange{12, 30}));
  // The real recordings' dx 7.15 mm at 20 kHz, 0.5-3 m/s: 143 / 3 = 47.67 -> 47,
  // 143 / 0.5 = 286.
  EXPECT_EQ(awcc::detail::awcc_lag_range(100'000, 7.15e-3, 20e3, velocity_range(0.5, 3.0)), (LagRange{47, 286}));
}

TEST(VelocityRange, BoundsThatAreWholeLagsStayAndOneUlpMovesThemOutward) {
  // dx = 2^-8 m and fs = 128 kHz make dx fs = 500 exactly: 500 / 50 = 10 and
  // 500 / 2 = 250 are whole lags and are the bounds themselves.
  const double dx = 1.0 / 256.0, fs = 128e3;
  ASSERT_EQ(dx * fs, 500.0);
  EXPECT_EQ(awcc::detail::awcc_lag_range(10'000, dx, fs, velocity_range(2.0, 50.0)), (LagRange{10, 250}));
  // u_max one ulp faster: its lag is just below 10, so lag 9 is searched too.
  EXPECT_EQ(awcc::detail::awcc_lag_range(10'000, dx, fs, velocity_range(2.0, std::nextafter(50.0, inf))).first, 9);
  EXPECT_EQ(awcc::detail::awcc_lag_range(10'000, dx, fs, velocity_range(2.0, std::nextafter(50.0, 0.0))).first, 10);
  // u_min one ulp slower: its lag is just above 250, so lag 251 is searched too.
  EXPECT_EQ(awcc::detail::awcc_lag_range(10'000, dx, fs, velocity_range(std::nextafter(2.0, 0.0), 50.0)).second, 251);
  EXPECT_EQ(awcc::detail::awcc_lag_range(10'000, dx, fs, velocity_range(std::nextafter(2.0, inf), 50.0)).second, 250);
}

TEST(VelocityRange, EveryVelocityOfTheRangeHasItsLagInsideAndTheRangeIsTight) {
  // Brute force over velocities spread across each range: the (fractional)
  // lag dx fs / u of every velocity in [u_min, u_max] lies in [k_min, k_max],
  // and neither bound can move inward by a lag without losing one.
  struct Case {
    double dx, fs, u_min, u_max;
  };
  for (const Case c : {Case{5e-3, 100e3, 2.0, 40.0}, Case{5e-3, 500e3, 1.0, 50.0}, Case{7.15e-3, 20e3, 0.3, 7.0},
                       Case{2e-3, 1e6, 3.3, 17.1}}) {
    const auto [k_min, k_max] = awcc::detail::awcc_lag_range(1'000'000, c.dx, c.fs, velocity_range(c.u_min, c.u_max));
    for (int i = 0; i <= 1000; ++i) {
      const double u = i == 1000 ? c.u_max : c.u_min + (c.u_max - c.u_min) * i / 1000.0;
      const double lag = c.dx * c.fs / u;
      ASSERT_GE(lag, static_cast<double>(k_min)) << "u " << u;
      ASSERT_LE(lag, static_cast<double>(k_max)) << "u " << u;
    }
    EXPECT_GT(static_cast<double>(k_min + 1), c.dx * c.fs / c.u_max);
    EXPECT_LT(static_cast<double>(k_max - 1), c.dx * c.fs / c.u_min);
  }
}

TEST(VelocityRange, WindowWhoseDelayIsOutsideTheRangeIsNotGivenThatVelocity) {
  // The trailing tip is the leading one delayed by 20 samples: at fs 1 kHz
  // and dx 1 m the true velocity is 1 / 0.020 = 50 m/s.
  const auto x = pdp_test::telegraph(20'000, 31, 1000.0);
  const auto y = pdp_test::shifted(x, 20);
  for (auto path : {awcc::CorrelationPath::intervals, awcc::CorrelationPath::fft}) {
    // 1-60 m/s: lags from floor(1000 / 60) = 16: the delay is inside and
    // every window finds it (so the signals do carry it).
    auto o = velocity_range(1.0, 60.0);
    o.filter_a = 0.0;
    o.roc = false;
    o.path = path;
    const auto inside = awcc::awcc(x, y, 1.0, o);
    ASSERT_GT(inside.windows.size(), 50u);
    for (const auto& w : inside.windows) {
      ASSERT_EQ(w.lag_samples, 20) << "window at " << w.start;
      EXPECT_DOUBLE_EQ(w.velocity, 50.0);
    }
    // 1-40 m/s: lags from floor(1000 / 40) = 25 to the window's end: lag 20
    // is not searched; no window may report it or its 50 m/s.
    o.velocity_max = 40.0;
    const auto outside = awcc::awcc(x, y, 1.0, o);
    ASSERT_EQ(outside.windows.size(), inside.windows.size());
    for (const auto& w : outside.windows) {
      ASSERT_NE(w.fate, WindowFate::constant);
      EXPECT_GE(w.lag_samples, 25) << "window at " << w.start;
      EXPECT_LE(w.lag_samples, w.length - 1) << "window at " << w.start;
      EXPECT_LE(w.velocity, 40.0) << "window at " << w.start;
    }
  }
}

// ---------------------------------------------------------------------------
// Windows too short for the velocity range.

TEST(WindowTooShortForTheVelocityRange, LagRangeIsEmptyWhenTheWindowEndsBeforeTheSlowestUsefulLag) {
  // dx 1 m, fs 1 kHz, 0.125-0.25 m/s: lags 1000 / 0.25 = 4000 to 8000. A
  // window of 4001 samples reaches lag 4000: one lag searched. One sample
  // shorter: nothing to search (k_max < k_min).
  const auto o = velocity_range(0.125, 0.25);
  EXPECT_EQ(awcc::detail::awcc_lag_range(4001, 1.0, 1000.0, o), (LagRange{4000, 4000}));
  const auto [k_min, k_max] = awcc::detail::awcc_lag_range(4000, 1.0, 1000.0, o);
  EXPECT_EQ(k_min, 4000);
  EXPECT_LT(k_max, k_min);
}

TEST(WindowTooShortForTheVelocityRange, HasItsOwnFateCountAndReason) {
  // Windows of Np = 10 chords of at most 50 samples (fs 1 kHz) are shorter
  // than 1000 samples; with dx 1 m and 0.125-0.25 m/s the first lag searched
  // is 4000: no window has a lag to search. The signals are not constant
  // (the trailing tip is the leading one delayed by 3 samples).
  const auto x = pdp_test::telegraph(20'000, 41, 1000.0);
  const auto y = pdp_test::shifted(x, 3);
  auto o = velocity_range(0.125, 0.25);
  const auto r = awcc::awcc(x, y, 1.0, o);
  ASSERT_GT(r.windows_total, 10);
  for (const auto& w : r.windows) {
    ASSERT_LT(w.length, 4001);
    // Not "constant" (issue 11): the signals vary; the window is too short.
    EXPECT_EQ(w.fate, WindowFate::too_short) << "window at " << w.start;
  }
  EXPECT_EQ(r.count(awcc::WindowFate::too_short), r.windows_total);
  EXPECT_EQ(r.count(awcc::WindowFate::constant), 0);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.status, awcc::AwccStatus::too_few_windows);
  EXPECT_NE(r.message.find(std::to_string(r.windows_total) + " too short for the velocity range"), std::string::npos)
      << r.message;
}


// ---------------------------------------------------------------------------
// A lag of one sample (awcc.hpp, least_resolved_lag_samples): an ok result
// whose accepted windows' mean lag sum w / sum (w / k_i) is below 1.5
// samples is quality low, with the velocity's bounds dx fs / 1.5 - dx fs / 0.5.

awcc::AwccWindow accepted_at(std::int64_t lag, double duration) {
  awcc::AwccWindow w;
  w.fate = WindowFate::accepted;
  w.lag_samples = lag;
  w.duration = duration;
  return w;
}

TEST(OneSampleLag, MeanLagIsTheWeightedHarmonicMeanOfTheAcceptedWindowsLags) {
  // Lags 1 (0.3 s), 2 (0.1 s) and 4 (0.6 s) accepted, one rejected at lag 1:
  // duration-weighted 1 / (0.3 / 1 + 0.1 / 2 + 0.6 / 4) = 1 / 0.5 = 2;
  // unweighted 3 / (1 + 1 / 2 + 1 / 4) = 12 / 7.
  std::vector<awcc::AwccWindow> w{accepted_at(1, 0.3), accepted_at(2, 0.1), accepted_at(4, 0.6), accepted_at(1, 5.0)};
  w.back().fate = WindowFate::roc;
  EXPECT_DOUBLE_EQ(awcc::detail::mean_lag_samples(w, awcc::Weighting::duration), 2.0);
  EXPECT_DOUBLE_EQ(awcc::detail::mean_lag_samples(w, awcc::Weighting::none), 12.0 / 7.0);
  // Equal weights at lags 1 and 2: 2 / (1 + 1 / 2) = 4 / 3, below the limit.
  const std::vector<awcc::AwccWindow> half{accepted_at(1, 1.0), accepted_at(2, 1.0)};
  EXPECT_DOUBLE_EQ(awcc::detail::mean_lag_samples(half, awcc::Weighting::none), 4.0 / 3.0);
  EXPECT_EQ(awcc::detail::mean_lag_samples(std::vector<awcc::AwccWindow>{}, awcc::Weighting::none), 0.0);
}

TEST(OneSampleLag, AMeanLagAtTheLimitIsMeasuredJustBelowIsBounded) {
  const auto judged_at = [](double lag) {
    awcc::AwccResult r;
    r.status = awcc::AwccStatus::ok;
    r.quality = awcc::AwccQuality::ok;
    r.velocity = 10.0;
    r.mean_lag_samples = lag;
    awcc::detail::flag_unresolved_lag(r, 0.6e-3, 27e3);  // dx fs = 16.2 m/s
    return r;
  };
  EXPECT_EQ(judged_at(awcc::least_resolved_lag_samples).quality, awcc::AwccQuality::ok);
  EXPECT_EQ(judged_at(3.0).quality, awcc::AwccQuality::ok);
  const auto r = judged_at(std::nextafter(awcc::least_resolved_lag_samples, 0.0));
  EXPECT_EQ(r.quality, awcc::AwccQuality::low);
  EXPECT_TRUE(r.ok());  // reported, flagged: the bound is worth having
  EXPECT_EQ(r.quality_reason.find("a lag of one sample: the accepted windows peak at a mean lag of 1.50 samples"), 0u)
      << r.quality_reason;
  EXPECT_NE(r.quality_reason.find("the velocity is bounded (10.8-32.4 m/s), not measured"), std::string::npos)
      << r.quality_reason;
  // A result with no velocity keeps its own status and reason.
  awcc::AwccResult none;
  none.mean_lag_samples = 1.0;
  none.quality_reason = "too few";
  awcc::detail::flag_unresolved_lag(none, 0.6e-3, 27e3);
  EXPECT_EQ(none.quality, awcc::AwccQuality::insufficient);
  EXPECT_EQ(none.quality_reason, "too few");
}

TEST(OneSampleLag, ATrailingTipOneSampleBehindIsBoundedTwoSamplesBehindIsNot) {
  // The trailing tip is the leading one delayed by 1 sample: every window
  // peaks at lag 1, u = dx fs = 1000 m/s with Tu 0, and all the record says
  // is that u lies in 667-2000 m/s. Delayed by 2 samples the mean lag is 2.
  const auto x = pdp_test::telegraph(200'000, 41, 1000.0);
  const auto one = awcc::awcc(x, pdp_test::shifted(x, 1), 1.0, awcc::AwccOptions{});
  ASSERT_TRUE(one.ok()) << one.message;
  EXPECT_DOUBLE_EQ(one.mean_lag_samples, 1.0);
  EXPECT_DOUBLE_EQ(one.velocity, 1000.0);
  EXPECT_EQ(one.quality, awcc::AwccQuality::low);
  EXPECT_NE(one.quality_reason.find("bounded (666.7-2000 m/s)"), std::string::npos) << one.quality_reason;
  const auto two = awcc::awcc(x, pdp_test::shifted(x, 2), 1.0, awcc::AwccOptions{});
  ASSERT_TRUE(two.ok()) << two.message;
  EXPECT_DOUBLE_EQ(two.mean_lag_samples, 2.0);
  EXPECT_EQ(two.quality_reason.find("a lag of one sample"), std::string::npos) << two.quality_reason;
}


// ---------------------------------------------------------------------------
// A chance yield (awcc.hpp, chance_data_yield): an ok result whose accepted
// windows are fewer than 0.1 % of those formed is quality low, saying the
// accepted windows may be chance peaks.

awcc::AwccResult summarised(std::int64_t accepted, std::int64_t total) {
  awcc::AwccResult r;
  for (std::int64_t i = 0; i < total; ++i) {
    awcc::AwccWindow w;
    w.duration = 0.01;
    w.lag_samples = 5;
    w.velocity = w.measured_velocity = 2.0 + 0.01 * static_cast<double>(i % 7);
    w.r12_max = 0.9;
    w.fate = i < accepted ? WindowFate::accepted : WindowFate::correlation;
    r.windows.push_back(w);
  }
  awcc::AwccOptions o;
  o.roc = false;
  awcc::detail::awcc_summarise(r, o);
  return r;
}

TEST(ChanceYield, TenOfTenThousandIsAtTheLimitOneMoreWindowFormedIsChance) {
  const auto at = summarised(10, 10'000);  // 0.1 % exactly
  ASSERT_TRUE(at.ok()) << at.message;
  EXPECT_FALSE(at.chance_yield);
  EXPECT_EQ(at.quality_reason.find("a chance yield"), std::string::npos) << at.quality_reason;
  const auto below = summarised(10, 10'001);
  ASSERT_TRUE(below.ok()) << below.message;
  EXPECT_TRUE(below.chance_yield);
  EXPECT_EQ(below.quality, awcc::AwccQuality::low);
  EXPECT_EQ(below.quality_reason.find("a chance yield: 10 of 10001 windows accepted (0.1 %, below 0.1 %)"), 0u)
      << below.quality_reason;
  // A yield far above chance keeps the generic reasons (here: fewer than 100 windows).
  const auto fine = summarised(50, 1'000);
  EXPECT_FALSE(fine.chance_yield);
  EXPECT_EQ(fine.quality_reason.find("50 accepted windows (fewer than 100)"), 0u) << fine.quality_reason;
  // Both rules: both reasons, the yield's first.
  auto both = summarised(10, 10'001);
  both.mean_lag_samples = 1.0;
  awcc::detail::flag_unresolved_lag(both, 0.6e-3, 27e3);
  EXPECT_TRUE(both.one_sample_lag && both.chance_yield);
  EXPECT_EQ(both.quality_reason.find("a chance yield: "), 0u) << both.quality_reason;
  EXPECT_NE(both.quality_reason.find("; a lag of one sample: "), std::string::npos) << both.quality_reason;
}

TEST(ChanceYield, SignalsThatShareNoBubbleAreFlaggedAndTheirOwnPairIsNot) {
  // The trailing tip of an unrelated record: whatever AWCC accepts is
  // chance. Reported from two windows (windows_reported 2), so that the
  // rule, not the window count, decides.
  const auto x = pdp_test::telegraph(1'600'000, 41, 1000.0);
  const auto unrelated = pdp_test::telegraph(1'600'000, 97, 1000.0);
  awcc::AwccOptions o;
  o.windows_reported = 2;
  const auto r = awcc::awcc(x, unrelated, 1.0, o);
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_LT(static_cast<double>(r.windows_accepted), awcc::chance_data_yield * static_cast<double>(r.windows_total));
  EXPECT_TRUE(r.chance_yield) << r.quality_reason;
  const auto own = awcc::awcc(x, pdp_test::shifted(x, 3), 1.0, o);
  ASSERT_TRUE(own.ok());
  EXPECT_FALSE(own.chance_yield);
}


// ---------------------------------------------------------------------------
// Binarisation at its thresholds. Convention (binarisation.cpp): with a single
// threshold T, a conductivity sample is air when V < T, an optical one when
// V > T; a sample exactly at T is water for both.

// 1 = air per sample of `v`, through the library's threshold choice and binariser.
std::vector<std::uint8_t> binarised(const std::vector<float>& v, const awcc::Threshold& t) {
  awcc::Binariser b(t, 1000.0);
  b.feed(v, 0, 1);
  return awcc::to_dense(b.finish());
}

awcc::Threshold threshold_for(const std::vector<float>& v, const awcc::BinarisationOptions& o) {
  awcc::VoltageHistogram h(1e-3);
  h.add(v, 0, 1);
  return awcc::choose_threshold(h, o);
}

TEST(FixedThreshold, SampleExactlyAtTheThresholdIsWaterForBothProbes) {
  // 2.5 V is exact in float, so the samples below sit exactly at, one float
  // ulp below and one above the threshold.
  const float t = 2.5f, below = std::nextafter(t, 0.0f), above = std::nextafter(t, 5.0f);
  const std::vector<float> v{4.0f, t, 4.0f, below, 4.0f, above, 4.0f, 1.0f, 4.0f};
  awcc::BinarisationOptions o;
  o.rule = awcc::ThresholdRule::fixed;
  o.fixed_threshold = 2.5;
  const auto conductivity = threshold_for(v, o);
  ASSERT_FALSE(conductivity.binary_input);
  EXPECT_EQ(conductivity.threshold, 2.5);
  // Conductivity: air is low, air when V < 2.5.
  EXPECT_EQ(binarised(v, conductivity), (std::vector<std::uint8_t>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  // Optical: air is high, air when V > 2.5.
  o.probe = awcc::ProbeType::optical;
  const auto optical = threshold_for(v, o);
  EXPECT_EQ(optical.threshold, 2.5);
  EXPECT_EQ(binarised(v, optical), (std::vector<std::uint8_t>{1, 0, 1, 0, 1, 1, 1, 0, 1}));
}

TEST(FelderThreshold, SampleLessThan1e5VoltAboveTheThresholdIsAir) {
  // Felder's program: air when V - threshold < 1e-5 V (conductivity). The
  // histogram below has 0.1 V bins labelled by their upper edge: air mode
  // label 1.1 V, water mode label 4.1 V, threshold 1.1 + 0.5 x 3.0 = 2.6 V.
  std::vector<float> v(600, 1.03f);
  v.insert(v.end(), 400, 4.03f);
  v.insert(v.end(), 5, 2.5f);
  awcc::BinarisationOptions o;
  o.rule = awcc::ThresholdRule::felder;
  const auto t = threshold_for(v, o);
  ASSERT_NEAR(t.threshold, 2.6, 1e-12);
  ASSERT_EQ(t.tolerance, 1e-5);
  // Float spacing near 2.6 V is 2.4e-7 V, far finer than the tolerance.
  const std::vector<float> probe{4.0f, 2.6f, 4.0f, 2.6f + 0.5e-5f, 4.0f, 2.6f + 2e-5f, 4.0f, 2.6f - 2e-5f, 4.0f};
  EXPECT_EQ(binarised(probe, t), (std::vector<std::uint8_t>{0, 1, 0, 1, 0, 0, 0, 1, 0}));
}

// A histogram with air and water modes in bins [1.0, 1.1) and [4.0, 4.1)
// (centres 1.05 and 4.05 V; span 3 V) and a few samples between.
std::vector<float> calibration_levels() {
  std::vector<float> v(600, 1.03f);
  v.insert(v.end(), 400, 4.03f);
  v.insert(v.end(), 5, 2.5f);
  return v;
}

TEST(Hysteresis, ConductivitySignalWigglingBetweenTheThresholdsDoesNotToggle) {
  awcc::BinarisationOptions o;
  o.rule = awcc::ThresholdRule::hysteresis;
  const auto t = threshold_for(calibration_levels(), o);
  // Air (low) 1.05 V, water 4.05 V: thresholds 1.05 + 0.4 x 3 = 2.25 V
  // (nearer air) and 1.05 + 0.6 x 3 = 2.85 V (nearer water).
  ASSERT_NEAR(t.air_level, 1.05, 1e-12);
  ASSERT_NEAR(t.water_level, 4.05, 1e-12);
  ASSERT_NEAR(t.lower, 2.25, 1e-12);
  ASSERT_NEAR(t.upper, 2.85, 1e-12);
  // The binariser compares float samples with the thresholds as floats.
  const float lo = static_cast<float>(t.lower), hi = static_cast<float>(t.upper);
  const float below_lo = std::nextafter(lo, 0.0f), above_hi = std::nextafter(hi, 5.0f);
  // Water -> air only below the lower threshold; air -> water only above the upper one.
  const std::vector<float> v{
      4.05f,                                                  // water
      hi, lo, 2.5f, lo, std::nextafter(lo, 5.0f), hi, 3.0f,  // wiggles down to lo exactly: stays water
      below_lo,                                               // crosses: air
      lo, hi, 2.5f, hi, std::nextafter(hi, 0.0f), 1.05f,     // wiggles up to hi exactly: stays air
      above_hi,                                               // crosses: water
      hi, lo, 3.0f};                                          // stays water
  const std::vector<std::uint8_t> expected{0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0};
  ASSERT_EQ(v.size(), expected.size());
  EXPECT_EQ(binarised(v, t), expected);
  // A single threshold at the middle toggles on the same wiggles.
  o.rule = awcc::ThresholdRule::histogram;
  const auto single = threshold_for(calibration_levels(), o);
  awcc::Binariser b(single, 1000.0);
  b.feed(v, 0, 1);
  EXPECT_GT(b.finish().intervals.size(), 2u);
}

TEST(Hysteresis, OpticalSignalWigglingBetweenTheThresholdsDoesNotToggle) {
  awcc::BinarisationOptions o;
  o.rule = awcc::ThresholdRule::hysteresis;
  o.probe = awcc::ProbeType::optical;
  const auto t = threshold_for(calibration_levels(), o);
  // Air (high) 4.05 V, water 1.05 V: 4.05 - 0.4 x 3 = 2.85 V (nearer air),
  // 4.05 - 0.6 x 3 = 2.25 V (nearer water).
  ASSERT_NEAR(t.air_level, 4.05, 1e-12);
  ASSERT_NEAR(t.water_level, 1.05, 1e-12);
  ASSERT_NEAR(t.lower, 2.25, 1e-12);
  ASSERT_NEAR(t.upper, 2.85, 1e-12);
  const float lo = static_cast<float>(t.lower), hi = static_cast<float>(t.upper);
  // Water -> air only above the upper threshold; air -> water only below the lower one.
  const std::vector<float> v{
      1.05f,                                                  // water
      lo, hi, 2.5f, hi, std::nextafter(hi, 0.0f), lo, 2.0f,  // wiggles up to hi exactly: stays water
      std::nextafter(hi, 5.0f),                               // crosses: air
      hi, lo, 2.5f, lo, std::nextafter(lo, 5.0f), 4.05f,     // wiggles down to lo exactly: stays air
      std::nextafter(lo, 0.0f),                               // crosses: water
      lo, hi, 2.0f};                                          // stays water
  const std::vector<std::uint8_t> expected{0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0};
  ASSERT_EQ(v.size(), expected.size());
  EXPECT_EQ(binarised(v, t), expected);
}

TEST(Hysteresis, CrossingBothThresholdsTogglesEveryTime) {
  // A full swing between the modes switches the state at every crossing, for
  // both probe types, exactly as the single threshold does: 5 low runs (air
  // for a conductivity probe) and 6 high runs (air for an optical one).
  std::vector<float> v;
  for (int i = 0; i < 5; ++i) {
    v.insert(v.end(), 7, 4.05f);
    v.insert(v.end(), 3, 1.05f);
  }
  v.insert(v.end(), 7, 4.05f);
  for (auto probe : {awcc::ProbeType::conductivity, awcc::ProbeType::optical}) {
    awcc::BinarisationOptions o;
    o.probe = probe;
    o.rule = awcc::ThresholdRule::hysteresis;
    const auto h = threshold_for(calibration_levels(), o);
    o.rule = awcc::ThresholdRule::histogram;
    const auto single = threshold_for(calibration_levels(), o);
    const auto a = binarised(v, h), b = binarised(v, single);
    EXPECT_EQ(a, b) << awcc::to_string(probe);
    awcc::Binariser count(h, 1000.0);
    count.feed(v, 0, 1);
    const std::size_t air_runs = probe == awcc::ProbeType::conductivity ? 5u : 6u;
    EXPECT_EQ(count.finish().intervals.size(), air_runs) << awcc::to_string(probe);
  }
}


// ---------------------------------------------------------------------------
// The edge and spread rules (awcc.hpp, lag_range_end_share and
// AwccResult::turbulence_measured): accepted windows at an end of the lags a
// velocity range lets AWCC search are counted, above 5 % of them the result
// is quality low; windows that all peak at one lag give no Tu.

// An ok result of `accepted` windows (fs 1 kHz, dx 1 m, 1,000 samples each),
// `at_least` of them at lag 4 and the rest spread over lags 5-19.
awcc::AwccResult with_windows_at_least_lag(int accepted, int at_least) {
  awcc::AwccResult r;
  r.status = awcc::AwccStatus::ok;
  r.quality = awcc::AwccQuality::ok;
  r.windows_accepted = accepted;
  for (int i = 0; i < accepted; ++i) {
    awcc::AwccWindow w = accepted_at(i < at_least ? 4 : 5 + i % 15, 1.0);
    w.length = 1000;
    w.lag = static_cast<double>(w.lag_samples) / 1000.0;
    r.windows.push_back(w);
  }
  return r;
}

TEST(LagRangeEnd, FivePercentAtAnEndIsFlaggedOneMoreWindowPilesUp) {
  // Velocity range 50-250 m/s at dx fs = 1000 m/s: lags searched 4-20.
  awcc::AwccOptions o;
  o.velocity_min = 50.0;
  o.velocity_max = 250.0;
  const auto [least, greatest] = awcc::detail::awcc_lag_range(1000, 1.0, 1000.0, o);
  ASSERT_EQ(least, 4);
  ASSERT_EQ(greatest, 20);
  auto at_limit = with_windows_at_least_lag(100, 5);
  awcc::detail::judge_lag_range_and_spread(at_limit, 1.0, 1000.0, o);
  EXPECT_EQ(at_limit.windows_at_least_lag, 5);
  EXPECT_EQ(at_limit.windows_at_greatest_lag, 0);
  EXPECT_FALSE(awcc::lags_pile_up_at_range_end(at_limit));
  EXPECT_EQ(at_limit.quality, awcc::AwccQuality::ok);
  auto beyond = with_windows_at_least_lag(100, 6);
  awcc::detail::judge_lag_range_and_spread(beyond, 1.0, 1000.0, o);
  EXPECT_TRUE(awcc::lags_pile_up_at_range_end(beyond));
  EXPECT_EQ(beyond.quality, awcc::AwccQuality::low);
  EXPECT_EQ(beyond.quality_reason.rfind("6 of 100 accepted windows peak at an end of the lags the velocity range "
                                        "50-250 m/s lets AWCC search (6 at the least lag",
                                        0),
            0u)
      << beyond.quality_reason;
  EXPECT_NE(beyond.quality_reason.find("(velocity-range)"), std::string::npos);
  // Without a velocity range the window's own reach bounds the lags: no end is counted.
  auto unranged = with_windows_at_least_lag(100, 50);
  awcc::detail::judge_lag_range_and_spread(unranged, 1.0, 1000.0, awcc::AwccOptions{});
  EXPECT_EQ(unranged.windows_at_least_lag + unranged.windows_at_greatest_lag, 0);
  EXPECT_EQ(unranged.quality, awcc::AwccQuality::ok);
}

// A trailing tip delayed by 8, 9, ..., 12 samples in turn (a segment of
// 20,000 samples each, repeated): windows peak at lags 8-12, u = dx fs / lag.
awcc::AirIntervals delayed_in_turn(const awcc::AirIntervals& x) {
  const auto dense = awcc::to_dense(x);
  std::vector<std::uint8_t> out(dense.size(), 0);
  for (std::size_t i = 0; i < dense.size(); ++i) {
    const std::size_t delay = 8 + (i / 20'000) % 5;
    if (i + delay < dense.size()) out[i + delay] = dense[i];
  }
  return awcc::from_dense(out, x.fs);
}

TEST(LagRangeEnd, PlantedDelaysBeyondTheRangePileUpAtItsEnd) {
  // dx fs = 1000 m/s: the delays of 8-12 samples are 83-125 m/s. A range of
  // 50-111 m/s searches lags 9-20: the windows of delays 8 and 9 (2 in 5)
  // peak at 9 (fewer than half at one lag: the outlier cutoff's spread
  // stays above 0). A range of 20-500 m/s (lags 2-50) holds every delay.
  const auto x = pdp_test::telegraph(400'000, 7, 1000.0);
  const auto y = delayed_in_turn(x);
  awcc::AwccOptions o;
  o.velocity_min = 50.0;
  o.velocity_max = 111.0;
  const auto clipped = awcc::awcc(x, y, 1.0, o);
  ASSERT_TRUE(clipped.ok()) << clipped.message;
  EXPECT_GT(clipped.windows_at_least_lag, clipped.windows_accepted / 4);
  EXPECT_EQ(clipped.windows_at_greatest_lag, 0);
  EXPECT_TRUE(awcc::lags_pile_up_at_range_end(clipped));
  EXPECT_EQ(clipped.quality, awcc::AwccQuality::low);
  EXPECT_TRUE(clipped.turbulence_measured) << clipped.quality_reason;  // lags 10-12 remain
  o.velocity_min = 20.0;
  o.velocity_max = 500.0;
  const auto held = awcc::awcc(x, y, 1.0, o);
  ASSERT_TRUE(held.ok()) << held.message;
  EXPECT_EQ(held.windows_at_least_lag + held.windows_at_greatest_lag, 0);
  EXPECT_FALSE(awcc::lags_pile_up_at_range_end(held));
  EXPECT_TRUE(held.turbulence_measured);
  EXPECT_GT(held.turbulence_intensity, 0.05);
}

TEST(TuNotMeasured, WindowsAtOneLagGiveNoTuAndAHalfSampleBoundTwoLagsGiveATu) {
  // Every window at lag 10 (dx fs = 1000 m/s): u = 100 m/s, u_rms 0 by the
  // lag's resolution; the delays lie in 9.5-10.5 samples, u in 95.2-105.3.
  const auto x = pdp_test::telegraph(200'000, 43, 1000.0);
  const auto one = awcc::awcc(x, pdp_test::shifted(x, 10), 1.0, awcc::AwccOptions{});
  ASSERT_TRUE(one.ok()) << one.message;
  EXPECT_FALSE(one.turbulence_measured);
  EXPECT_EQ(one.quality, awcc::AwccQuality::low);
  EXPECT_NEAR(one.velocity, 100.0, 1e-12);
  EXPECT_DOUBLE_EQ(one.velocity_ci95.lower, 1000.0 / 10.5);
  EXPECT_DOUBLE_EQ(one.velocity_ci95.upper, 1000.0 / 9.5);
  EXPECT_NE(one.quality_reason.find("peaks at the same lag, 10 samples"), std::string::npos) << one.quality_reason;
  // Five lags (delays of 8-12 samples in turn): a spread, measured.
  const auto spread = awcc::awcc(x, delayed_in_turn(x), 1.0, awcc::AwccOptions{});
  ASSERT_TRUE(spread.ok()) << spread.message;
  EXPECT_TRUE(spread.turbulence_measured);
  EXPECT_GT(spread.turbulence_intensity, 0.05);
  // More than half the windows at one lag: the outlier cutoff's spread
  // estimate (1.4826 MAD) is 0 and it rejects every other lag; the rule
  // says so (a record delayed by 10 samples for 60 %, then by 11).
  const auto dense = awcc::to_dense(x);
  std::vector<std::uint8_t> mostly(dense.size(), 0);
  for (std::size_t i = 0; i + 11 < dense.size(); ++i) mostly[i + (i < dense.size() * 3 / 5 ? 10 : 11)] = dense[i];
  const auto collapsed = awcc::awcc(x, awcc::from_dense(mostly, x.fs), 1.0, awcc::AwccOptions{});
  ASSERT_TRUE(collapsed.ok()) << collapsed.message;
  EXPECT_FALSE(collapsed.turbulence_measured);
  EXPECT_GT(collapsed.count(WindowFate::roc), 0);
  EXPECT_NE(collapsed.quality_reason.find("the outlier cutoff rejected the other"), std::string::npos)
      << collapsed.quality_reason;
  // With the peak refined, windows of one whole-sample lag keep their own
  // sub-sample lags (the rule reads the lags the velocities come from): a
  // spread is measured, and for a copy delayed by exactly 10 samples it is
  // small (the correlation's peak is a triangle only near its top).
  awcc::AwccOptions refined;
  refined.subsample = awcc::Subsample::triangle;
  const auto r = awcc::awcc(x, pdp_test::shifted(x, 10), 1.0, refined);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.turbulence_measured);
  EXPECT_LT(r.turbulence_intensity, 0.01);
}

}  // namespace
