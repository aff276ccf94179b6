// A row's one list of warnings (awcc/assess.hpp, awcc/flags.hpp): the flag
// table, the list assembled from every source in order, the FSCC/AWCC
// disagreement rule at its limit (on each side, with FSCC's asymmetric
// interval), FSCC's sampling interval against a reference computed here, the
// E4 advice that fits the row, and the channels a recording holds beyond the
// tip pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <numbers>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "awcc/assess.hpp"
#include "awcc/fscc.hpp"
#include "awcc/process.hpp"
#include "awcc/read_back.hpp"
#include "awcc/random.hpp"
#include "awcc/velocity_series.hpp"
#include "random_signals.hpp"
#include "signal_builders.hpp"
#include "test_paths.hpp"

namespace {

bool mentions(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(Flags, TableIsInEnumOrderWithDistinctCodesAndTheProfileColumnListsThem) {
  std::set<std::string_view> codes;
  for (std::size_t i = 0; i < awcc::flag_names.size(); ++i) {
    const auto& f = awcc::flag_names[i];
    EXPECT_EQ(static_cast<std::size_t>(f.flag), i);
    EXPECT_EQ(awcc::to_string(f.flag), f.code);
    EXPECT_TRUE(codes.insert(f.code).second) << f.code << " twice";
    EXPECT_FALSE(f.meaning.empty()) << f.code;
    // A code is one word of the field: it joins a CSV cell with "; " and splits back.
    EXPECT_EQ(f.code.find_first_of(" ;,"), std::string_view::npos) << f.code;
  }
  const auto listed = awcc::written_values(awcc::profile_column::flags);
  EXPECT_EQ(std::set<std::string_view>(listed.begin(), listed.end()), codes);
}

TEST(Flags, CellOfCodesParsesBackAndAnUnknownCodeIsRefused) {
  const awcc::WrittenAt at{"profile.csv", "line 3", "flags"};
  EXPECT_TRUE(awcc::parse_flags_cell("", at).empty());
  const auto flags = awcc::parse_flags_cell("reader_note; methods_disagree; integral_scale_short", at);
  EXPECT_EQ(flags, (std::vector{awcc::Flag::reader_note, awcc::Flag::methods_disagree,
                                awcc::Flag::integral_scale_short}));
  try {
    awcc::parse_flags_cell("reader_note; E4", at);
    ADD_FAILURE() << "an unknown code accepted";
  } catch (const awcc::InputError& e) {
    EXPECT_TRUE(mentions(e.what(), "profile.csv") && mentions(e.what(), "line 3") && mentions(e.what(), "'E4'"))
        << e.what();
  }
}

// FSCC ok at 2 m/s with the interval [1.9, 2.2] (asymmetric, as dx / lag
// makes it), and AWCC ok at `velocity` +/- 0.05 m/s.
awcc::FsccResult fscc_at_2() {
  awcc::FsccResult f;
  f.status = awcc::FsccStatus::ok;
  f.velocity = 2.0;
  f.lag = 3e-3;
  f.velocity_ci95 = awcc::Interval95{1.9, 2.2};
  return f;
}

awcc::AwccResult awcc_at(double velocity, awcc::AwccQuality quality = awcc::AwccQuality::ok) {
  awcc::AwccResult a;
  a.status = awcc::AwccStatus::ok;
  a.quality = quality;
  a.velocity = velocity;
  a.velocity_ci95 = {velocity - 0.05, velocity + 0.05};
  a.windows_accepted = quality == awcc::AwccQuality::ok ? 400 : 12;
  a.windows_total = 500;
  return a;
}

TEST(MethodsDisagree, AtTheLimitOnEachSideWithTheIntervalsSidesThatFaceEachOther) {
  // AWCC below FSCC: FSCC's lower half-width 0.1 and AWCC's upper 0.05 combine to hypot(0.1, 0.05).
  const double below = std::sqrt(0.1 * 0.1 + 0.05 * 0.05);
  const auto f = fscc_at_2();
  for (const double eps : {1e-9, -1e-9}) {
    const auto c = awcc::compare_methods(f, awcc_at(2.0 - below * (1.0 + eps)));
    ASSERT_TRUE(c);
    EXPECT_NEAR(c->allowed, below, 1e-12);
    EXPECT_EQ(c->disagree(), eps > 0) << eps;
  }
  // AWCC above: FSCC's upper half-width 0.2 faces it, hypot(0.2, 0.05); a
  // difference of 0.15 exceeds the lower side's 0.112 but not this.
  const double above = std::sqrt(0.2 * 0.2 + 0.05 * 0.05);
  EXPECT_FALSE(awcc::compare_methods(f, awcc_at(2.15))->disagree());
  for (const double eps : {1e-9, -1e-9}) {
    const auto c = awcc::compare_methods(f, awcc_at(2.0 + above * (1.0 + eps)));
    EXPECT_NEAR(c->allowed, above, 1e-12);
    EXPECT_EQ(c->disagree(), eps > 0) << eps;
  }
  // Exactly at the limit (binary-exact numbers, half-widths 0.5 and 0.375
  // combining to 0.625): not beyond it; a step further is.
  awcc::FsccResult exact = f;
  exact.velocity_ci95 = awcc::Interval95{1.5, 2.5};
  auto a = awcc_at(1.375);
  a.velocity_ci95 = {1.0, 1.75};
  const auto at_limit = awcc::compare_methods(exact, a);
  EXPECT_EQ(at_limit->allowed, 0.625);
  EXPECT_EQ(at_limit->difference, -0.625);
  EXPECT_FALSE(at_limit->disagree());
  EXPECT_EQ(at_limit->relative, 0.3125);
  a.velocity = std::nextafter(1.375, 0.0);
  EXPECT_TRUE(awcc::compare_methods(exact, a)->disagree());
}

TEST(MethodsDisagree, ComparedWhenBothGiveAVelocityAndFsccAnInterval) {
  const auto f = fscc_at_2();
  EXPECT_TRUE(awcc::compare_methods(f, awcc_at(1.0, awcc::AwccQuality::low)));  // low quality: compared
  auto insufficient = awcc_at(1.0);
  insufficient.status = awcc::AwccStatus::too_few_windows;  // no velocity
  insufficient.quality = awcc::AwccQuality::insufficient;
  EXPECT_FALSE(awcc::compare_methods(f, insufficient));
  auto no_interval = f;
  no_interval.velocity_ci95.reset();
  EXPECT_FALSE(awcc::compare_methods(no_interval, awcc_at(1.0)));
  auto failed = f;
  failed.status = awcc::FsccStatus::no_positive_peak;
  EXPECT_FALSE(awcc::compare_methods(failed, awcc_at(1.0)));
}

awcc::ProcessResult row(const awcc::FsccResult& f, const awcc::AwccResult& a) {
  awcc::ProcessResult r;
  r.info.channels = 2;
  r.tips.resize(2);
  r.tips[1].channel = 1;
  r.fscc = f;
  r.awcc = a;
  return r;
}

TEST(MethodsDisagree, TheWarningGivesBothValuesBothIntervalsAndTheRelativeDifference) {
  auto a = awcc_at(1.6, awcc::AwccQuality::low);
  a.windows.push_back({.lag = 4.0e-3, .fate = awcc::WindowFate::accepted});
  a.windows.push_back({.lag = 9.0e-3, .fate = awcc::WindowFate::roc});
  a.windows.push_back({.lag = 4.5e-3, .fate = awcc::WindowFate::accepted});
  const auto warnings = awcc::assess(row(fscc_at_2(), a));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].flag, awcc::Flag::methods_disagree);
  const auto& t = warnings[0].text;
  for (const char* part : {"1.600 m/s", "1.550-1.650", "2.000 m/s", "1.900-2.200", "differ by 0.400 m/s",
                           "AWCC 20 % below FSCC", "(0.112 m/s)", "lags 4.00-4.50 ms", "FSCC's whole record at 3.00 ms",
                           "12 accepted windows of 500 (quality low)", "chord lengths and d32 use FSCC's velocity"}) {
    EXPECT_TRUE(mentions(t, part)) << "'" << part << "' not in: " << t;
  }
  // Quality ok: the advice is the correction's, not the windows'.
  const auto ok = awcc::assess(row(fscc_at_2(), awcc_at(2.4)));
  ASSERT_EQ(ok.size(), 1u);
  EXPECT_TRUE(mentions(ok[0].text, "AWCC 20 % above FSCC")) << ok[0].text;
  EXPECT_TRUE(mentions(ok[0].text, "bias correction")) << ok[0].text;
  EXPECT_FALSE(mentions(ok[0].text, "quality low")) << ok[0].text;
  EXPECT_FALSE(mentions(ok[0].text, "accepted windows peak at")) << ok[0].text;  // many windows: no lag range
  // Within the limit: no warning.
  EXPECT_TRUE(awcc::assess(row(fscc_at_2(), awcc_at(2.1))).empty());
}

TEST(Assess, CollectsEverySourceInOrderWithItsFlagAndText) {
  auto r = row(fscc_at_2(), awcc_at(1.0, awcc::AwccQuality::low));
  r.info.warnings = {"the header promises 10 s; 8 s present", "values read as counts"};
  r.fscc->warnings = {"FSCC velocity 120 m/s is above 100 m/s"};
  r.spectrum.emplace();
  r.spectrum->status = awcc::SpectrumStatus::ok;
  r.spectrum->integral_time_scale = 1e-3;
  r.spectrum->warning = "the velocity's integral time scale is 0.25 mean window durations";
  r.info.channels = 3;
  const auto w = awcc::assess(r);
  std::vector<awcc::Flag> flags;
  for (const auto& x : w) flags.push_back(x.flag);
  EXPECT_EQ(flags, (std::vector{awcc::Flag::reader_note, awcc::Flag::reader_note, awcc::Flag::channels_ignored,
                                awcc::Flag::fscc_implausible, awcc::Flag::integral_scale_short,
                                awcc::Flag::methods_disagree}));
  EXPECT_EQ(w[0].text, r.info.warnings[0]);
  EXPECT_EQ(w[1].text, r.info.warnings[1]);
  EXPECT_EQ(w[3].text, r.fscc->warnings[0]);
  EXPECT_EQ(w[4].text, r.spectrum->warning);
  // No time scale: the spectrum's warning is of the undefined kind.
  r.spectrum->integral_time_scale.reset();
  EXPECT_EQ(awcc::assess(r)[4].flag, awcc::Flag::integral_scale_undefined);
}

// The sampling interval from the segments' peak lags, against the formula of
// awcc/fscc.hpp worked here with a two-pass standard deviation.
TEST(FsccInterval, SegmentsPeakLagsGiveTheStudentIntervalWithTheRoundingInQuadrature) {
  const double fs = 20e3, dx = 7.15e-3;
  const std::vector<std::int64_t> lags{57, 52, 61, 55, 58, 49, 66, 57, 54, 60};
  const double lag = 57.0 / fs;
  double mean = 0.0;
  for (auto k : lags) mean += static_cast<double>(k) / 10.0;
  double var = 0.0;
  for (auto k : lags) var += (static_cast<double>(k) - mean) * (static_cast<double>(k) - mean) / 9.0;
  const double half = std::sqrt(std::pow(2.262 * std::sqrt(var / 10.0), 2) + 0.475 * 0.475) / fs;
  const auto i = awcc::fscc_velocity_interval(lags, lag, fs, dx);
  ASSERT_TRUE(i);
  EXPECT_NEAR(i->lower, dx / (lag + half), 1e-12);
  EXPECT_NEAR(i->upper, dx / (lag - half), 1e-12);
  EXPECT_LT(i->lower, dx / lag);
  EXPECT_GT(i->upper - dx / lag, dx / lag - i->lower);  // u = dx / tau: wider above

  // Five segments: t(0.975, 4) = 2.776.
  const std::vector<std::int64_t> five{57, 52, 61, 55, 58};
  double m5 = 0.0, v5 = 0.0;
  for (auto k : five) m5 += static_cast<double>(k) / 5.0;
  for (auto k : five) v5 += (static_cast<double>(k) - m5) * (static_cast<double>(k) - m5) / 4.0;
  const double h5 = std::sqrt(std::pow(2.776 * std::sqrt(v5 / 5.0), 2) + 0.475 * 0.475) / fs;
  EXPECT_NEAR(awcc::fscc_velocity_interval(five, lag, fs, dx)->lower, dx / (lag + h5), 1e-12);

  // Equal lags: the rounding alone, 0.475 samples.
  const std::vector<std::int64_t> equal(10, 57);
  EXPECT_NEAR(awcc::fscc_velocity_interval(equal, lag, fs, dx)->upper, dx / (lag - 0.475 / fs), 1e-12);
  // Four segments give no interval; neither does a lag interval reaching 0.
  EXPECT_FALSE(awcc::fscc_velocity_interval(std::vector<std::int64_t>{57, 52, 61, 55}, lag, fs, dx));
  EXPECT_FALSE(awcc::fscc_velocity_interval(std::vector<std::int64_t>{2, 300, 5, 250, 1, 280}, 3.0 / fs, fs, dx));
}

TEST(FsccInterval, BinaryFsccCarriesItFromItsSegments) {
  // A random telegraph signal and its copy 40 samples later: every segment
  // peaks at 40, so the interval is the rounding's alone.
  const auto lead = pdp_test::telegraph(200'000, 7, 20e3);
  const auto trail = pdp_test::shifted(lead, 40);
  const auto f = awcc::fscc(lead, trail, 5e-3);
  ASSERT_TRUE(f.ok()) << f.message;
  ASSERT_TRUE(f.velocity_ci95);
  EXPECT_EQ(f.interval_segments, awcc::fscc_interval_segments);
  EXPECT_NEAR(f.velocity_ci95->lower, 5e-3 / ((40 + 0.475) / 20e3), 1e-12);
  EXPECT_NEAR(f.velocity_ci95->upper, 5e-3 / ((40 - 0.475) / 20e3), 1e-12);
}

// The E4 warning's advice: the np that would do, or that none would, and
// whether the accepted windows are few.
TEST(E4Advice, NamesTheNpThatWouldDoOrSaysNoneWouldAndWhetherTheWindowsAreFew) {
  awcc::AwccResult a;
  a.status = awcc::AwccStatus::ok;
  a.np = 10;
  a.windows_accepted = 23;  // file 04: ratio 1.27
  const auto few = awcc::detail::windows_too_long(a, 1.27);
  EXPECT_TRUE(mentions(few, "1.27 mean window durations")) << few;
  EXPECT_TRUE(mentions(few, "np = 6 particles or fewer (now 10)")) << few;  // 10 x 1.27 / 2 = 6.35
  EXPECT_TRUE(mentions(few, "rests on 23 accepted windows (quality ok needs 100)")) << few;
  EXPECT_FALSE(mentions(few, "not resolved")) << few;
  a.windows_accepted = 355;  // file 10: ratio 0.24
  const auto unresolved = awcc::detail::windows_too_long(a, 0.24);
  EXPECT_TRUE(mentions(unresolved, "not resolved")) << unresolved;
  EXPECT_TRUE(mentions(unresolved, "np = 1.2 or fewer (now 10), under the 3 particles")) << unresolved;
  EXPECT_FALSE(mentions(unresolved, "rests on")) << unresolved;
  EXPECT_FALSE(mentions(unresolved, "particles or fewer")) << unresolved;
  // Around the least np, 3: ratio 0.61 allows np = 3.05, so 3; 0.58 allows 2.9, so none.
  EXPECT_TRUE(mentions(awcc::detail::windows_too_long(a, 0.61), "np = 3 particles or fewer"));
  EXPECT_TRUE(mentions(awcc::detail::windows_too_long(a, 0.58), "np = 2.9 or fewer (now 10), under"));
}

// A recording of four channels, the tips on two of them.
std::unique_ptr<awcc::Recording> four_channels() {
  const auto lead = awcc::to_dense(pdp_test::telegraph(40'000, 3, 20e3, 40, 200));
  std::vector<float> frames;
  for (std::size_t i = 0; i < lead.size(); ++i) {
    for (std::size_t c = 0; c < 4; ++c) {
      const std::size_t j = i >= 10 * c ? i - 10 * c : 0;  // channel c: 10 c samples later
      frames.push_back(lead[j] ? 0.3f : 4.0f);
    }
  }
  return awcc::memory_recording(std::move(frames), 4, 20e3, "four.dat");
}

TEST(ChannelsIgnored, AFourChannelRecordingNamesTheChannelsNotProcessed) {
  awcc::ProcessOptions o;
  o.dx = 5e-3;
  o.awcc = false;
  auto recording = four_channels();
  const auto r = awcc::process_recording(*recording, o);
  // The telegraph's tips are air 3 in 4 of the time: each also carries the
  // signal check's air_continuous flag, which is not this test's.
  std::vector<awcc::Warning> kept;
  for (const auto& x : r.warnings) {
    if (x.flag != awcc::Flag::signal_check) kept.push_back(x);
  }
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].flag, awcc::Flag::channels_ignored);
  EXPECT_EQ(kept[0].text,
            "channels 2 and 3 of 4 are not processed (a 4-tip probe?): the tip pair alone was processed, channels 0 "
            "and 1; to process every tip as a probe of four or more, declare their positions (tips, tip-channels)");
  o.trailing_channel = 3;
  const auto other = awcc::process_recording(*recording, o);
  const auto ignored = std::find_if(other.warnings.begin(), other.warnings.end(),
                                    [](const awcc::Warning& x) { return x.flag == awcc::Flag::channels_ignored; });
  ASSERT_NE(ignored, other.warnings.end());
  EXPECT_TRUE(mentions(ignored->text, "channels 1 and 2 of 4 are not processed"));
  // Two channels: nothing ignored.
  o.trailing_channel = 1;
  std::vector<float> two;
  for (int i = 0; i < 4000; ++i) {
    two.push_back((i / 50) % 2 ? 0.3f : 4.0f);
    two.push_back(((i + 5) / 50) % 2 ? 0.3f : 4.0f);
  }
  const auto pair = awcc::process_recording(*awcc::memory_recording(std::move(two), 2, 20e3), o);
  EXPECT_TRUE(std::none_of(pair.warnings.begin(), pair.warnings.end(),
                           [](const awcc::Warning& w) { return w.flag == awcc::Flag::channels_ignored; }));
}

}  // namespace

awcc::EventResult events_at(double velocity, awcc::Interval95 ci) {
  awcc::EventResult e;
  e.status = awcc::EventStatus::ok;
  e.quality = awcc::AwccQuality::ok;
  e.velocity = velocity;
  e.velocity_ci95 = ci;
  e.bubbles_paired = 500;
  e.bubbles_complete = 900;
  return e;
}

TEST(EventsDisagree, AgainstFsccAtTheLimitElseAwccOfQualityOkElseNotCompared) {
  // Binary-exact: FSCC 2 m/s [1.5, 2.5], event detection 1.375 [1.0, 1.75]:
  // half-widths 0.5 and 0.375 facing each other combine to 0.625, the
  // difference exactly: not beyond; a step further is.
  auto f = fscc_at_2();
  f.velocity_ci95 = awcc::Interval95{1.5, 2.5};
  const auto r = row(f, awcc_at(2.0));
  const auto at_limit = awcc::compare_events(events_at(1.375, {1.0, 1.75}), r);
  ASSERT_TRUE(at_limit);
  EXPECT_EQ(at_limit->reference, "FSCC");
  EXPECT_EQ(at_limit->allowed, 0.625);
  EXPECT_FALSE(at_limit->disagree());
  EXPECT_TRUE(awcc::compare_events(events_at(std::nextafter(1.375, 0.0), {1.0, 1.75}), r)->disagree());
  // Above FSCC: its upper half-width faces event detection's lower one.
  const auto above = awcc::compare_events(events_at(3.0, {2.875, 3.25}), r);
  EXPECT_EQ(above->allowed, std::hypot(0.5, 0.125));
  EXPECT_TRUE(above->disagree());
  // Without FSCC's interval: AWCC of quality ok is the reference; of quality low, none.
  auto no_interval = f;
  no_interval.velocity_ci95.reset();
  auto a = awcc_at(2.0);
  EXPECT_EQ(awcc::compare_events(events_at(1.0, {0.9, 1.1}), row(no_interval, a))->reference, "AWCC");
  a.quality = awcc::AwccQuality::low;
  EXPECT_FALSE(awcc::compare_events(events_at(1.0, {0.9, 1.1}), row(no_interval, a)));
  // Event detection without a velocity is not compared.
  auto none = events_at(1.0, {0.9, 1.1});
  none.status = awcc::EventStatus::too_few_bubbles;
  EXPECT_FALSE(awcc::compare_events(none, r));
}

TEST(EventsDisagree, TheWarningIsInTheRowsListWithItsFlag) {
  auto r = row(fscc_at_2(), awcc_at(2.0));
  r.events = events_at(1.0, {0.95, 1.05});
  const auto w = awcc::assess(r);
  const auto it = std::find_if(w.begin(), w.end(), [](const awcc::Warning& x) { return x.flag == awcc::Flag::events_disagree; });
  ASSERT_NE(it, w.end());
  EXPECT_NE(it->text.find("event detection's velocity 1.000 m/s"), std::string::npos) << it->text;
  EXPECT_NE(it->text.find("use FSCC's velocity"), std::string::npos) << it->text;
  r.events = events_at(2.0, {1.9, 2.1});
  const auto agree = awcc::assess(r);
  EXPECT_TRUE(std::none_of(agree.begin(), agree.end(), [](const awcc::Warning& x) { return x.flag == awcc::Flag::events_disagree; }));
}

TEST(EventsDisagree, TheMeanIsCarriedToFsccsPeakAndADifferenceWithinTheModelsToleranceCounts) {
  // The peak of the lag density for u ~ N(U, (Tu U)^2): U (1 + sqrt(1 + 8 Tu^2)) / 2.
  EXPECT_DOUBLE_EQ(awcc::correlation_peak_velocity(2.0, 0.0), 2.0);
  EXPECT_DOUBLE_EQ(awcc::correlation_peak_velocity(1.0, 0.3), (1.0 + std::sqrt(1.72)) / 2.0);
  // Brute force: the density's maximum over a fine lag grid (dx = 1, U = 1, Tu = 0.3).
  double best_tau = 0.0, best = -1.0;
  for (int k = 1; k < 200000; ++k) {
    const double tau = 0.5 + k * 1e-5;
    const double z = (1.0 / tau - 1.0) / 0.3;
    const double p = std::exp(-0.5 * z * z) / (tau * tau);
    if (p > best) best = p, best_tau = tau;
  }
  EXPECT_NEAR(1.0 / best_tau, awcc::correlation_peak_velocity(1.0, 0.3), 1e-4);
  // A mean of 2 m/s at Tu 0.3 (narrow intervals) is expected in [u_F / g,
  // u_F], g = 1.1557: inside it at either end; above it by 11 % of u_F
  // (u_F = 1.8) a disagreement, by 8 % (u_F = 1.85) within the tolerance;
  // below it by 7 % (band from 2.18) not, by 17 % (band from 2.5) it is.
  const double g = awcc::correlation_peak_velocity(1.0, 0.3);
  auto narrow_fscc = [](double v) {
    auto f = fscc_at_2();
    f.velocity = v;
    f.velocity_ci95 = awcc::Interval95{v - 1e-3, v + 1e-3};
    return f;
  };
  auto e = events_at(2.0, {1.999, 2.001});
  e.turbulence_intensity = 0.3;
  auto against = [&](double fscc) { return *awcc::compare_events(e, row(narrow_fscc(fscc), awcc_at(2.0))); };
  EXPECT_EQ(against(2.0).difference, 0.0);
  EXPECT_FALSE(against(2.0).disagree());
  EXPECT_NEAR(against(2.0 * g).band_lower, 2.0, 1e-12);
  EXPECT_FALSE(against(2.0 * g).disagree());
  EXPECT_TRUE(against(1.8).disagree());
  EXPECT_FALSE(against(1.85).disagree());
  EXPECT_FALSE(against(2.18 * g).disagree());
  EXPECT_TRUE(against(2.5 * g).disagree());
  // A Tu beyond 0.3 (a mis-paired record's) does not widen the band.
  e.turbulence_intensity = 1.5;
  EXPECT_NEAR(against(2.5 * g).band_lower, 2.5, 1e-12);
  EXPECT_TRUE(against(2.5 * g).disagree());
}

TEST(MultiTipDoubtful, TheStreamwiseComponentAgainstFsccAndTheQualityInTheRowsList) {
  awcc::MultiTipResult v;
  v.status = awcc::MultiTipStatus::ok;
  v.velocity = {1.375, 0.0, 0.0};
  v.velocity_ci95[0] = {1.0, 1.75};
  auto f = fscc_at_2();
  f.velocity_ci95 = awcc::Interval95{1.5, 2.5};
  auto r = row(f, awcc_at(2.0));
  const auto at_limit = awcc::compare_multi_tip(v, r);
  ASSERT_TRUE(at_limit);
  EXPECT_EQ(at_limit->allowed, 0.625);
  EXPECT_FALSE(at_limit->disagree());
  v.velocity[0] = std::nextafter(1.375, 0.0);
  EXPECT_TRUE(awcc::compare_multi_tip(v, r)->disagree());
  // Only a low quality reaches the row's warnings.
  awcc::ProbeResult probe;
  probe.vectors = v;
  probe.quality = awcc::AwccQuality::ok;
  r.probe = probe;
  auto w = awcc::assess(r);
  EXPECT_TRUE(std::none_of(w.begin(), w.end(), [](const awcc::Warning& x) { return x.flag == awcc::Flag::multi_tip_doubtful; }));
  r.probe->quality = awcc::AwccQuality::low;
  r.probe->quality_reason = "because";
  w = awcc::assess(r);
  const auto it = std::find_if(w.begin(), w.end(), [](const awcc::Warning& x) { return x.flag == awcc::Flag::multi_tip_doubtful; });
  ASSERT_NE(it, w.end());
  EXPECT_NE(it->text.find("is doubtful: because"), std::string::npos) << it->text;
}

namespace {

// A tip's longest chord against single_phase_stretch_factor times its chords'
// mean times the log of their count (awcc/assess.hpp), for air and water, on
// each side of the limit, and the least count of chords the rule reads.
std::vector<awcc::Warning> stretch_warnings(std::int64_t count, double mean, double max, bool water) {
  auto r = row(fscc_at_2(), awcc_at(2.0, awcc::AwccQuality::ok));
  auto& s = water ? r.tips[1].phase.water_chord_time : r.tips[1].phase.air_chord_time;
  s.count = count;
  s.mean = mean;
  s.max = max;
  std::vector<awcc::Warning> out;
  for (auto& w : awcc::assess(r)) {
    if (w.flag == awcc::Flag::long_single_phase) out.push_back(std::move(w));
  }
  return out;
}

TEST(LongSinglePhase, AtTheLimitOnEachSideForAirAndWater) {
  const double mean = 2e-3, limit = awcc::single_phase_stretch_factor * mean * std::log(1000.0);
  for (const bool water : {false, true}) {
    EXPECT_TRUE(stretch_warnings(1000, mean, limit, water).empty()) << water;
    const auto w = stretch_warnings(1000, mean, limit * (1 + 1e-9), water);
    ASSERT_EQ(w.size(), 1u) << water;
    EXPECT_TRUE(mentions(w[0].text, "channel 1 (trailing tip): one "));
    EXPECT_TRUE(mentions(w[0].text, water ? "water chord lasts 0.207 s, 15 times" : "air chord lasts 0.207 s"))
        << w[0].text;
    EXPECT_TRUE(mentions(w[0].text, "cut the record")) << w[0].text;
  }
  // Below 20 chords the log of their count says too little: no rule.
  const double few = 100 * mean * std::log(19.0);
  EXPECT_TRUE(stretch_warnings(19, mean, few, false).empty());
  EXPECT_EQ(stretch_warnings(20, mean, few, false).size(), 1u);
}

// The real dc157_05.dat (45 s at 20 kHz; a UQ .dat: 8 bytes of header, then
// int16 pairs) and its bytes, which the acquisition-fault tests alter.
std::filesystem::path real_recording() {
  return pdp_test::source_dir().parent_path() / "shared" / "data" / "felder-stepped-spillway" / "dc157_05.dat";
}

std::vector<char> bytes_of(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A real recording (dc157_05) with 5 s of its 45 s replaced by the air level
// (the probe lifted out of the flow): flagged on both tips; the recording
// itself is not (its longest chords are 2-4 times m ln n).
TEST(LongSinglePhase, AProbeLiftedOutOfTheFlowIsFlaggedOnARealRecording) {
  const auto source = real_recording();
  if (!std::filesystem::exists(source)) GTEST_SKIP() << "the real recordings are not at " << source;
  auto bytes = bytes_of(source);
  awcc::ProcessOptions o;
  o.reader.fs = 20e3;
  o.dx = 7.15e-3;
  const auto flagged = [&](const std::filesystem::path& p) {
    int n = 0;
    for (const auto& w : awcc::assess(awcc::process_recording(p, o))) n += w.flag == awcc::Flag::long_single_phase;
    return n;
  };
  EXPECT_EQ(flagged(source), 0);
  // 8 bytes of header, then int16 pairs; the air level is near 5,000 counts on both channels.
  for (std::size_t k = 300000; k < 400000; ++k) {
    for (std::size_t c = 0; c < 2; ++c) {
      const std::int16_t air = 5000;
      std::memcpy(bytes.data() + 8 + 4 * k + 2 * c, &air, 2);
    }
  }
  const auto lifted = pdp_test::test_file("lifted.dat");
  std::ofstream(lifted, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  EXPECT_EQ(flagged(lifted), 2);
}

// What else an acquisition does to a recording mid-record (issue 53): a gain
// or an offset that changes halfway, electrical noise, mains hum on a working
// probe. Each is refused by the signal check's flat-level rule
// (awcc/signal_check.hpp) naming the channel, not read as bubbles. The real
// dc157_05 is first halved about 16,000 counts so that nothing clips.
TEST(AcquisitionFaults, AGainOrOffsetChangeNoiseOrHumIsRefusedAsNoFlatLevel) {
  const auto source = real_recording();
  if (!std::filesystem::exists(source)) GTEST_SKIP() << "the real recordings are not at " << source;
  auto bytes = bytes_of(source);
  const std::size_t n = (bytes.size() - 8) / 4;
  std::vector<double> x(2 * n);
  for (std::size_t k = 0; k < 2 * n; ++k) {
    std::int16_t v = 0;
    std::memcpy(&v, bytes.data() + 8 + 2 * k, 2);
    x[k] = (v - 16000.0) * 0.5 + 16000.0;
  }
  // The levels after halving: water about 21,500 and air about 10,600 counts.
  const double separation = 10900.0;
  awcc::Rng rng(53, 0);
  const std::vector<std::pair<std::string, std::function<double(std::size_t, double)>>> faults{
      {"gain", [&](std::size_t k, double v) { return k >= n ? v * 0.8 : v; }},
      {"offset", [&](std::size_t k, double v) { return k >= n ? v - 0.15 * separation : v; }},
      {"noise", [&](std::size_t, double v) { return v + 0.15 * separation * rng.normal(); }},
      {"hum", [&](std::size_t k, double v) {
         return v + 0.2 * separation * std::sin(2 * std::numbers::pi * 50.0 * static_cast<double>(k / 2) / 20e3);
       }}};
  awcc::ProcessOptions o;
  o.reader.fs = 20e3;
  o.dx = 7.15e-3;
  for (const auto& [name, fault] : faults) {
    auto out = bytes;
    for (std::size_t k = 0; k < 2 * n; ++k) {
      const auto v = static_cast<std::int16_t>(std::clamp(std::round(fault(k, x[k])), -32767.0, 32766.0));
      std::memcpy(out.data() + 8 + 2 * k, &v, 2);
    }
    const auto path = pdp_test::test_file(name + ".dat");
    std::ofstream(path, std::ios::binary).write(out.data(), static_cast<std::streamsize>(out.size()));
    try {
      awcc::process_recording(path, o);
      ADD_FAILURE() << name << ": processed";
    } catch (const awcc::InputError& e) {
      EXPECT_TRUE(mentions(e.what(), "channel 0 (leading tip): the voltage histogram has no flat level")) << e.what();
      EXPECT_TRUE(mentions(e.what(), name + ".dat")) << e.what();
    }
  }
}

}  // namespace

TEST(EventResolution, LagsSpreadLessThanATenthOfASampleAreNoMeasuredTu) {
  // judge_events's resolution rule at and around its limit: 100 paired
  // bubbles at 20 kHz whose centre lags (in samples) alternate 5 -/+ h have
  // the sample sd h sqrt(100 / 99); Tu is measured from 0.1 of a sample on.
  auto judged = [](double h) {
    awcc::EventResult e;
    e.status = awcc::EventStatus::ok;
    e.quality = awcc::AwccQuality::ok;
    for (int i = 0; i < 100; ++i) {
      awcc::EventBubble b;
      b.fate = awcc::BubbleFate::paired;
      b.centre_lag = (5.0 + (i % 2 == 0 ? -h : h)) / 20e3;
      e.bubbles.push_back(b);
    }
    awcc::ProcessResult out;
    out.info.fs = 20e3;
    awcc::judge_events(e, out);
    return e;
  };
  const double at = awcc::least_crossing_spread * std::sqrt(99.0 / 100.0);
  const auto below = judged(0.999 * at);
  EXPECT_FALSE(below.turbulence_measured);
  EXPECT_EQ(below.quality, awcc::AwccQuality::low);
  EXPECT_NE(below.quality_reason.find("less than the 0.1 the interface times resolve"), std::string::npos)
      << below.quality_reason;
  EXPECT_TRUE(judged(1.001 * at).turbulence_measured);
  EXPECT_TRUE(judged(0.5).turbulence_measured);  // whole-sample lags 4.5 / 5.5
}
