// Every way an FSCC or AWCC result can come out undefined (fscc.cpp, awcc.cpp,
// process.cpp): the smallest signal that triggers it, `defined == false` and
// the reason. One case per TEST, so that replacing defined/reason by a status
// (issue 11) changes each in one place.
#include "awcc/detail/awcc_steps.hpp"
#include <gtest/gtest.h>

#include <string>

#include "awcc/awcc.hpp"
#include "awcc/fscc.hpp"
#include "awcc/process.hpp"
#include "random_signals.hpp"
#include "signal_builders.hpp"

namespace {

using awcc::AirIntervals;
using awcc::WindowFate;
using pdp_test::shifted;
using pdp_test::telegraph;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A defined FSCC result for contrast: the same builders with a planted delay.
TEST(FsccStatus, PlantedPositiveDelayIsDefinedWithoutReason) {
  const auto x = telegraph(10'000, 3);
  const auto r = awcc::fscc(x, shifted(x, 5), 1.0, {});
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.message.empty()) << r.message;
  EXPECT_EQ(r.lag_samples, 5);
}

TEST(FsccStatus, LeadingTipWithoutBubblesIsUndefined) {
  const auto y = telegraph(10'000, 3);
  const auto r = awcc::fscc(pdp_test::all_water_like(y), y, 1.0, {});
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.message, "the leading tip's signal is constant")) << r.message;
  EXPECT_EQ(r.status, awcc::FsccStatus::constant_leading);
  EXPECT_EQ(r.velocity, 0.0);
}

TEST(FsccStatus, LeadingTipAllAirIsUndefined) {
  const auto y = telegraph(10'000, 3);
  AirIntervals air = pdp_test::all_water_like(y);
  air.intervals = {{0, air.sample_count}};
  const auto r = awcc::fscc(air, y, 1.0, {});
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.message, "the leading tip's signal is constant")) << r.message;
  EXPECT_EQ(r.status, awcc::FsccStatus::constant_leading);
}

TEST(FsccStatus, TrailingTipWithoutBubblesIsUndefined) {
  const auto x = telegraph(10'000, 3);
  const auto r = awcc::fscc(x, pdp_test::all_water_like(x), 1.0, {});
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.message, "the trailing tip's signal is constant")) << r.message;
  EXPECT_EQ(r.status, awcc::FsccStatus::constant_trailing);
}

TEST(FsccStatus, NoSegmentWithBubblesOnBothTipsIsUndefined) {
  // Two segments of 10,000 samples: the leading tip has bubbles in the first
  // only, the trailing tip in the second only. Neither signal is constant
  // over the record.
  const auto bubbles = telegraph(10'000, 4);
  AirIntervals x, y;
  x.fs = y.fs = bubbles.fs;
  x.sample_count = y.sample_count = 20'000;
  x.intervals = bubbles.intervals;
  for (const auto& iv : bubbles.intervals) y.intervals.push_back({iv.start + 10'000, iv.stop + 10'000});
  awcc::FsccOptions o;
  o.segments = 2;
  const auto r = awcc::fscc(x, y, 1.0, o);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.message, "no segment holds bubbles on both tips")) << r.message;
  EXPECT_EQ(r.status, awcc::FsccStatus::no_common_segment);
  // Either tip's bubbles over both segments: defined.
  const auto both = awcc::fscc(x, shifted(x, 3), 1.0, o);
  EXPECT_TRUE(both.ok()) << both.message;
}

TEST(FsccStatus, NoPositivePeakIsUndefined) {
  // The trailing tip is the complement of a square wave of period 1000 on
  // the leading tip: y - my = -(x - mx), so R12 = -R11 exactly. R11 of the
  // square wave is a triangle, 1 - 4 |k| / 1000, times the overlap
  // (n - |k|) / n: above 0.59 over lags -100..100, so R12 < -0.59 there.
  const auto x = pdp_test::square_wave(10'000, 500, 500, 1000.0);
  awcc::FsccOptions o;
  o.max_lag = 0.1;
  const auto r = awcc::fscc(x, pdp_test::complement(x), 1.0, o);
  EXPECT_FALSE(r.ok());
  EXPECT_LT(r.r12_max, -0.59);
  EXPECT_TRUE(contains(r.message, "no positive peak")) << r.message;
  EXPECT_EQ(r.status, awcc::FsccStatus::no_positive_peak);
}

TEST(FsccStatus, PeakAtNegativeLagIsUndefined) {
  // Tips swapped: the "leading" signal is the later one.
  const auto x = telegraph(10'000, 3);
  const auto r = awcc::fscc(shifted(x, 5), x, 1.0, {});
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.lag_samples, -5);
  EXPECT_TRUE(contains(r.message, "peaks at lag -5 samples (not positive)")) << r.message;
  EXPECT_EQ(r.status, awcc::FsccStatus::tips_swapped);
  EXPECT_TRUE(contains(r.message, "check the tip order")) << r.message;
}

TEST(FsccStatus, PeakAtLagZeroIsUndefinedAndAtLagOneIsDefined) {
  const auto x = telegraph(10'000, 3);
  const auto zero = awcc::fscc(x, x, 1.0, {});
  EXPECT_FALSE(zero.ok());
  EXPECT_EQ(zero.lag_samples, 0);
  EXPECT_TRUE(contains(zero.message, "peaks at lag 0 samples (not positive)")) << zero.message;
  EXPECT_EQ(zero.status, awcc::FsccStatus::non_positive_lag);
  const auto one = awcc::fscc(x, shifted(x, 1), 1.0, {});
  EXPECT_TRUE(one.ok()) << one.message;
  EXPECT_EQ(one.lag_samples, 1);
}

TEST(FsccStatus, PeakAtTheEndOfTheLagRangeIsUndefinedOneLagInsideIsDefined) {
  // Chords of 200-400 samples: R12 is a broad hill around the planted delay.
  // Lags searched -20..20 (max lag 20 ms at 1 kHz).
  const auto x = telegraph(40'000, 5, 1000.0, 200, 200, 200);
  awcc::FsccOptions o;
  o.max_lag = 0.02;
  const auto at_end = awcc::fscc(x, shifted(x, 20), 1.0, o);
  EXPECT_FALSE(at_end.ok());
  EXPECT_EQ(at_end.lag_samples, 20);
  EXPECT_TRUE(contains(at_end.message, "peaks at the end of the lag range: the delay lies beyond the lags searched, or dx's unit or the sampling rate is wrong")) << at_end.message;
  EXPECT_EQ(at_end.status, awcc::FsccStatus::peak_at_lag_range_end);
  const auto beyond = awcc::fscc(x, shifted(x, 50), 1.0, o);
  EXPECT_FALSE(beyond.ok());
  EXPECT_TRUE(contains(beyond.message, "end of the lag range")) << beyond.message;
  EXPECT_EQ(beyond.status, awcc::FsccStatus::peak_at_lag_range_end);
  const auto inside = awcc::fscc(x, shifted(x, 19), 1.0, o);
  EXPECT_TRUE(inside.ok()) << inside.message;
  EXPECT_EQ(inside.lag_samples, 19);
}

// The two tips of a recording, binarised, for process_binarised.
awcc::BinarisedRecording binarised(const AirIntervals& leading, const AirIntervals& trailing) {
  awcc::BinarisedRecording r;
  r.info.fs = leading.fs;
  r.info.channels = 2;
  r.info.frames = leading.sample_count;
  r.leading = leading;
  r.trailing = trailing;
  return r;
}

TEST(FsccStatus, NoTipSeparationGivenIsUndefined) {
  const auto x = telegraph(10'000, 3);
  awcc::ProcessOptions o;
  o.dx = 0.0;
  const auto r = awcc::process_binarised(binarised(x, shifted(x, 5)), o);
  ASSERT_TRUE(r.fscc.has_value());
  EXPECT_FALSE(r.fscc->ok());
  EXPECT_EQ(r.fscc->status, awcc::FsccStatus::no_tip_separation);
  // The library speaks of the quantity; the command line adds the flag.
  EXPECT_EQ(r.fscc->message, "no tip separation given: the velocity cannot be computed");
  EXPECT_EQ(r.fscc->velocity, 0.0);
  // With dx, the same signals are defined.
  o.dx = 5e-3;
  EXPECT_TRUE(awcc::process_binarised(binarised(x, shifted(x, 5)), o).fscc->ok());
}

// ---------------------------------------------------------------------------
// AWCC.

// A leading tip with `bubbles` complete air chords (10 samples of air every
// 50), starting and ending in water: 2 x bubbles transitions.
AirIntervals bubbles(int count) {
  AirIntervals s;
  s.fs = 1000.0;
  s.sample_count = 50 * (count + 1);
  for (int i = 0; i < count; ++i) s.intervals.push_back({50 * i + 20, 50 * i + 30});
  return s;
}

TEST(AwccStatus, FewerThanNpParticlesIsUndefined) {
  // Np = 10 needs 2 Np = 20 transitions of the leading tip for one window.
  // Nine bubbles and a tenth cut by the record's end: 19 transitions.
  AirIntervals x = bubbles(9);
  x.intervals.push_back({x.sample_count, x.sample_count + 10});
  x.sample_count += 10;  // the tenth bubble runs to the end
  ASSERT_TRUE(x.check().empty()) << x.check();
  ASSERT_TRUE(awcc::awcc_windows(x, 10).empty());
  const auto r = awcc::awcc(x, shifted(x, 2), 1.0, {});
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.windows_total, 0);
  EXPECT_TRUE(contains(r.message, "fewer than Np = 10 particles on the leading tip")) << r.message;
  EXPECT_EQ(r.status, awcc::AwccStatus::too_few_particles);
  // Ten complete bubbles, 20 transitions: one window (undefined for another reason).
  EXPECT_EQ(awcc::awcc_windows(bubbles(10), 10).size(), 1u);
  const auto one = awcc::awcc(bubbles(10), shifted(bubbles(10), 2), 1.0, {});
  EXPECT_EQ(one.windows_total, 1);
  EXPECT_FALSE(contains(one.message, "fewer than Np")) << one.message;
}

TEST(AwccStatus, MostWindowsAtLagZeroIsUndefined) {
  // Identical tips: the delay is below one sample in every window.
  const auto x = telegraph(50'000, 8);
  const auto r = awcc::awcc(x, x, 1.0, {});
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.lag_zero_windows, r.windows_total);
  EXPECT_TRUE(contains(r.message, "most windows peak at lag 0")) << r.message;
  EXPECT_EQ(r.status, awcc::AwccStatus::delay_below_one_sample);
  EXPECT_TRUE(contains(r.message, "shorter than one sample")) << r.message;
}

// Windows with the given fates (lag samples 0 for `lag` windows marked zero).
awcc::AwccResult summarised(const std::vector<std::pair<WindowFate, std::int64_t>>& windows,
                            int windows_reported = 2) {
  awcc::AwccResult r;
  for (const auto& [fate, lag] : windows) {
    awcc::AwccWindow w;
    w.fate = fate;
    w.lag_samples = lag;
    w.duration = 1.0;
    w.velocity = lag > 0 ? 1000.0 / static_cast<double>(lag) : 0.0;
    r.windows.push_back(w);
  }
  awcc::AwccOptions o;
  o.roc = false;
  o.windows_reported = windows_reported;
  awcc::detail::awcc_summarise(r, o);
  return r;
}

TEST(AwccStatus, LagZeroReasonNeedsMoreThanHalfTheWindows) {
  using F = WindowFate;
  // 3 of 5 windows at lag 0: more than half.
  const auto most = summarised({{F::lag, 0}, {F::lag, 0}, {F::lag, 0}, {F::correlation, 5}, {F::correlation, 6}});
  EXPECT_FALSE(most.ok());
  EXPECT_TRUE(contains(most.message, "most windows peak at lag 0")) << most.message;
  // 2 of 4: exactly half is not most; the general reason with the counts.
  const auto half = summarised({{F::lag, 0}, {F::lag, 0}, {F::correlation, 5}, {F::correlation, 6}});
  EXPECT_FALSE(half.ok());
  EXPECT_FALSE(contains(half.message, "lag 0")) << half.message;
  EXPECT_TRUE(contains(half.message, "0 of 4 windows accepted (2 rejected by the correlation filter, 2 by a "
                                    "non-positive lag")) << half.message;
  EXPECT_EQ(half.status, awcc::AwccStatus::too_few_windows);
}

TEST(AwccStatus, NoWindowPassesTheCorrelationFilterIsUndefined) {
  // A planted positive delay, but A = 1: no window's R12max / (SPR^2 + 1)
  // reaches 1 (a window correlation misses the samples shifted across its edge).
  const auto x = telegraph(50'000, 9);
  awcc::AwccOptions o;
  o.filter_a = 1.0;
  const auto r = awcc::awcc(x, shifted(x, 5), 1.0, o);
  EXPECT_FALSE(r.ok());
  ASSERT_GT(r.windows_total, 10);
  EXPECT_EQ(r.count(awcc::WindowFate::correlation), r.windows_total);
  const std::string n = std::to_string(r.windows_total);
  EXPECT_TRUE(contains(r.message, "0 of " + n + " windows accepted (" + n + " rejected by the correlation filter"))
      << r.message;
  EXPECT_EQ(r.status, awcc::AwccStatus::too_few_windows);
  EXPECT_TRUE(contains(r.message, "too few for statistics")) << r.message;
}

TEST(AwccStatus, EveryWindowAtNegativeLagIsUndefined) {
  // Tips swapped: every window peaks at -5 samples.
  const auto x = telegraph(50'000, 9);
  const auto r = awcc::awcc(shifted(x, 5), x, 1.0, {});
  EXPECT_FALSE(r.ok());
  ASSERT_GT(r.windows_total, 10);
  EXPECT_EQ(r.count(awcc::WindowFate::lag), r.windows_total);
  EXPECT_EQ(r.lag_zero_windows, 0);
  for (const auto& w : r.windows) EXPECT_LT(w.lag_samples, 0);
  // Most windows at negative lags: the tips are swapped (METHOD 4, item 10).
  EXPECT_EQ(r.status, awcc::AwccStatus::tips_swapped);
  EXPECT_EQ(r.negative_lag_windows, r.windows_total);
  EXPECT_TRUE(contains(r.message, "have it at a negative lag: the trailing tip's signal leads")) << r.message;
  EXPECT_EQ(r.quality, awcc::AwccQuality::insufficient);
}

// Swapped tips at the limit: clear negative-lag windows must exceed the
// positive ones by more than 3 sqrt(n) (n clear windows), the 3-sd excess of
// signals with no direction. 30 negative, 10 positive: 20 > 3 sqrt(40) =
// 18.97: swapped. 29 and 11: 18 < 18.97: not. Unclear negative peaks (below
// the filter) count for nothing.
TEST(AwccStatus, SwappedTipsNeedASignificantExcessOfNegativeLags) {
  using F = WindowFate;
  auto with = [](int negative, int positive, double r12) {
    awcc::AwccResult r;
    for (int i = 0; i < negative + positive; ++i) {
      awcc::AwccWindow w;
      w.duration = 1.0;
      w.r12_max = r12;
      w.lag_samples = i < negative ? -4 : 4 + i % 2;
      w.fate = i < negative ? F::lag : F::accepted;
      w.velocity = w.lag_samples > 0 ? 1000.0 / static_cast<double>(w.lag_samples) : 0.0;
      r.windows.push_back(w);
    }
    awcc::AwccOptions o;
    o.roc = false;
    awcc::detail::awcc_summarise(r, o);
    return r;
  };
  EXPECT_EQ(with(30, 10, 0.9).status, awcc::AwccStatus::tips_swapped);
  EXPECT_EQ(with(29, 11, 0.9).status, awcc::AwccStatus::ok) << with(29, 11, 0.9).message;
  EXPECT_EQ(with(30, 10, 0.3).status, awcc::AwccStatus::ok);  // below A = 0.4: no clear peaks
}

// The quality levels at their limits (METHOD 4, item 10): windows_reported
// (10) and windows_ok (100) accepted windows, and a yield of yield_ok (5 %).
TEST(AwccQuality, LevelsAtTheirLimits) {
  using F = WindowFate;
  auto with = [](int accepted, int rejected) {
    std::vector<std::pair<F, std::int64_t>> w;
    for (int i = 0; i < accepted; ++i) w.emplace_back(F::accepted, 4 + i % 3);
    for (int i = 0; i < rejected; ++i) w.emplace_back(F::correlation, 5);
    return summarised(w, 10);
  };
  EXPECT_EQ(with(9, 0).quality, awcc::AwccQuality::insufficient);
  EXPECT_FALSE(with(9, 0).ok());
  EXPECT_EQ(with(10, 0).quality, awcc::AwccQuality::low);
  EXPECT_TRUE(with(10, 0).ok());
  EXPECT_EQ(with(99, 0).quality, awcc::AwccQuality::low);
  EXPECT_EQ(with(100, 0).quality, awcc::AwccQuality::ok);
  // Yield: 100 of 2000 windows is exactly 5 %: ok; 100 of 2001 is below: low.
  EXPECT_EQ(with(100, 1900).quality, awcc::AwccQuality::ok);
  const auto low = with(100, 1901);
  EXPECT_EQ(low.quality, awcc::AwccQuality::low);
  EXPECT_NE(low.quality_reason.find("data yield 5.0 %"), std::string::npos) << low.quality_reason;
}

TEST(AwccStatus, TrailingTipConstantInEveryWindowIsUndefined) {
  const auto x = telegraph(50'000, 8);
  const auto r = awcc::awcc(x, pdp_test::all_water_like(x), 1.0, {});
  EXPECT_FALSE(r.ok());
  ASSERT_GT(r.windows_total, 10);
  EXPECT_EQ(r.count(awcc::WindowFate::constant), r.windows_total);
  EXPECT_TRUE(contains(r.message, std::to_string(r.windows_total) + " constant): too few for statistics")) << r.message;
  for (double v : {r.velocity, r.velocity_rms, r.turbulence_intensity}) EXPECT_EQ(v, 0.0);
}

TEST(AwccStatus, OneAcceptedWindowIsUndefinedTwoAreDefined) {
  using F = WindowFate;
  const auto one = summarised({{F::accepted, 5}, {F::correlation, 5}, {F::correlation, 6}});
  EXPECT_FALSE(one.ok());
  EXPECT_TRUE(contains(one.message, "1 of 3 windows accepted (2 rejected by the correlation filter")) << one.message;
  EXPECT_EQ(one.status, awcc::AwccStatus::too_few_windows);
  const auto two = summarised({{F::accepted, 5}, {F::accepted, 4}, {F::correlation, 6}});
  EXPECT_TRUE(two.ok()) << two.message;
  EXPECT_TRUE(two.message.empty());
  // Equal durations: the mean of 200 and 250 m/s.
  EXPECT_DOUBLE_EQ(two.velocity, 225.0);
}

TEST(AwccStatus, NoTipSeparationGivenIsUndefined) {
  const auto x = telegraph(50'000, 9);
  awcc::ProcessOptions o;
  o.dx = 0.0;
  o.awcc = true;
  o.fscc = false;
  const auto r = awcc::process_binarised(binarised(x, shifted(x, 5)), o);
  ASSERT_TRUE(r.awcc.has_value());
  EXPECT_FALSE(r.awcc->ok());
  EXPECT_EQ(r.awcc->status, awcc::AwccStatus::no_tip_separation);
  EXPECT_EQ(r.awcc->message, "no tip separation given: the velocity cannot be computed");
  o.dx = 5e-3;
  const auto with_dx = awcc::process_binarised(binarised(x, shifted(x, 5)), o);
  EXPECT_TRUE(with_dx.awcc->ok()) << with_dx.awcc->message;
}

}  // namespace
