// End-to-end processing: synthetic recordings with known truth, the real
// spillway recordings against an independent straightforward computation,
// and bad input.
#include "awcc/detail/awcc_steps.hpp"
#include "awcc/serialise.hpp"
#include "awcc/process.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <map>

#include "synth/recording.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"
#include "result_warnings.hpp"
#include "signal_builders.hpp"

namespace {

using pdp_test::signal_texts;


namespace fs = std::filesystem;

fs::path spillway_dir() { return pdp_test::source_dir().parent_path() / "shared" / "data" / "felder-stepped-spillway"; }

struct Written {
  synth::Synthesis synthesis;
  fs::path path;
};

Written write_scene(const synth::Scene& s, synth::SignalKind signal, const std::string& name) {
  Written w{synth::synthesise(s), pdp_test::temp_dir() / name};
  synth::RecordingOptions o;
  o.signal = signal;
  o.format = *synth::format_from_extension(w.path);
  synth::write_recording(w.path, s, w.synthesis.signals, o);
  return w;
}

std::int64_t complete_air_chords(const awcc::AirIntervals& s) {
  std::int64_t n = 0;
  for (const auto& iv : s.intervals) n += iv.start > 0 && iv.stop < s.sample_count;
  return n;
}

TEST(ProcessSynthetic, BinaryFileGivesTheTruthExactly) {
  synth::Scene s;
  s.duration = 2.0;
  s.tu = 0.05;
  s.tu_y = s.tu_z = 0.025;
  s.dy = 0.0;
  const auto w = write_scene(s, synth::SignalKind::binary, "process_binary.flac");
  awcc::ProcessOptions o;
  o.dx = s.dx;
  const auto r = awcc::process_recording(w.path, o);
  ASSERT_EQ(r.tips.size(), 2u);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_TRUE(r.tips[j].threshold.binary_input);
    EXPECT_DOUBLE_EQ(r.tips[j].phase.void_fraction, w.synthesis.truth.tips[j].void_fraction);
    EXPECT_DOUBLE_EQ(r.tips[j].phase.bubble_count_rate,
                     static_cast<double>(complete_air_chords(w.synthesis.signals[j])) / s.duration);
  }
  // Delay: transit dx / u = 250 samples. The FSCC peak sits at the most
  // frequent transit time; with Tu = 0.05 the transit times spread by +/- 5 %
  // around 250 samples and the mode of dx/u lies within 2 Tu^2 = 0.5 % of
  // dx/u_mean; one sample of quantisation is 0.4 %. So 2 % is a safe bound.
  ASSERT_TRUE(r.fscc && r.fscc->ok()) << r.fscc->message;
  EXPECT_NEAR(r.fscc->velocity / w.synthesis.truth.realised.mean_velocity[0], 1.0, 0.02);
  EXPECT_GT(r.fscc->r12_max, 0.5);
}

TEST(ProcessSynthetic, VoltageFileIsBinarisedBackToTheTruth) {
  // Raw voltage with first-order edges (tau = 2 us, 0.2 samples at 100 kHz)
  // and 0.02 V noise against a 3.7 V step: the 50 % threshold is crossed
  // within one sample of each true edge and noise never reaches it (0.02 V vs
  // 1.85 V: 90 sd). Each chord can gain or lose at most one sample at each end
  // but the shifts of both edges are equal, so c changes by at most
  // (number of chords) / N; chords are counted exactly.
  synth::Scene s;
  s.duration = 2.0;
  s.fs = 100e3;
  const auto w = write_scene(s, synth::SignalKind::voltage, "process_voltage.wav");
  awcc::ProcessOptions o;
  o.dx = s.dx;
  o.reader.volts_per_count = s.voltage_full_scale / 32768.0;  // no sidecar beside this file
  const auto r = awcc::process_recording(w.path, o);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_FALSE(r.tips[j].threshold.binary_input);
    const auto& truth = w.synthesis.signals[j];
    const double bound = static_cast<double>(truth.intervals.size()) / static_cast<double>(truth.sample_count);
    EXPECT_NEAR(r.tips[j].phase.void_fraction, truth.void_fraction(), bound);
    EXPECT_DOUBLE_EQ(r.tips[j].phase.bubble_count_rate, static_cast<double>(complete_air_chords(truth)) / s.duration);
    // Modes are bin centres of 0.1 V bins next to the levels 0.3 V and 4.0 V
    // (the noise puts each level on a bin edge, either side may win).
    EXPECT_NEAR(r.tips[j].threshold.air_level, 0.3, 0.05 + 1e-9);
    EXPECT_NEAR(r.tips[j].threshold.water_level, 4.0, 0.05 + 1e-9);
  }
}

TEST(ProcessSynthetic, RawVoltageCorrelationAgreesWithBinary) {
  // The raw voltage carries the same interfaces as the binary signal, blurred
  // by a 2 us response and 0.02 V noise: window lags agree within a sample in
  // nearly every window and the mean velocity within 1 %.
  synth::Scene s;
  s.duration = 2.0;
  s.dy = 0.0;
  s.tu = 0.1;
  s.tu_y = s.tu_z = 0.02;  // little lateral drift: the tips see the same chords
  const auto w = write_scene(s, synth::SignalKind::voltage, "process_raw.w64");
  awcc::ProcessOptions o;
  o.dx = s.dx;
  o.fscc = false;
  o.awcc = true;
  o.reader.volts_per_count = s.voltage_full_scale / 32768.0;
  const auto binary = awcc::process_recording(w.path, o);
  o.awcc_options.signal = awcc::CorrelationSignal::raw;
  const auto raw = awcc::process_recording(w.path, o);
  ASSERT_TRUE(binary.awcc && raw.awcc);
  ASSERT_TRUE(binary.awcc->ok() && raw.awcc->ok()) << raw.awcc->message;
  ASSERT_EQ(binary.awcc->windows.size(), raw.awcc->windows.size());
  // Windows the binary path accepts have a clear peak; the raw path finds it
  // too (rejected windows peak anywhere, in both).
  std::size_t close = 0, accepted = 0;
  for (std::size_t i = 0; i < raw.awcc->windows.size(); ++i) {
    if (binary.awcc->windows[i].fate != awcc::WindowFate::accepted) continue;
    ++accepted;
    close += std::llabs(raw.awcc->windows[i].lag_samples - binary.awcc->windows[i].lag_samples) <= 1;
  }
  ASSERT_GT(accepted, 50u);
  EXPECT_GT(close, accepted * 95 / 100);
  EXPECT_NEAR(raw.awcc->velocity / binary.awcc->velocity, 1.0, 0.01);
}

// --- The real recordings -------------------------------------------------

struct Independent {
  double void_fraction;
  double bubble_count_rate;
  double threshold;
};

// Straight from METHOD 2, without the library: 0.1 V bins, modes below and
// above the middle of the observed range at bin centres, threshold halfway,
// air below it; complete air runs per second.
Independent independent(const fs::path& path, int channel) {
  std::ifstream in(path, std::ios::binary);
  std::int32_t rows = 0, channels = 0;
  in.read(reinterpret_cast<char*>(&rows), 4);
  in.read(reinterpret_cast<char*>(&channels), 4);
  std::vector<std::int16_t> data(static_cast<std::size_t>(rows) * static_cast<std::size_t>(channels));
  in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(data.size() * 2));
  std::vector<double> v;
  for (std::int32_t i = 0; i < rows; ++i) v.push_back(data[static_cast<std::size_t>(i * channels + channel)] * 5.0 / 32768.0);
  double lo = v[0], hi = v[0];
  for (double x : v) {
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  std::map<long, long> bins;
  for (double x : v) ++bins[static_cast<long>(std::floor(x / 0.1))];
  const double middle = (lo + hi) / 2;
  long air_bin = 0, water_bin = 0, air_count = -1, water_count = -1;
  for (auto [bin, count] : bins) {
    const double centre = (static_cast<double>(bin) + 0.5) * 0.1;
    if (centre < middle && count > air_count) air_bin = bin, air_count = count;
    if (centre >= middle && count > water_count) water_bin = bin, water_count = count;
  }
  const double threshold = ((static_cast<double>(air_bin) + 0.5) * 0.1 + (static_cast<double>(water_bin) + 0.5) * 0.1) / 2;
  long air = 0, runs = 0;
  bool in_air = false;
  long start = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const bool a = v[i] < threshold;
    air += a;
    if (a && !in_air) start = static_cast<long>(i);
    if (!a && in_air && start > 0) ++runs;  // a run that began at sample 0 is cut
    in_air = a;
  }
  return {static_cast<double>(air) / rows, static_cast<double>(runs) / (rows / 20000.0), threshold};
}

class Spillway : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::is_directory(spillway_dir())) {
      GTEST_SKIP() << "the real recordings are not here: " << spillway_dir() << " (they sit beside the repository in CI)";
    }
  }
  static fs::path file(int i) { return spillway_dir() / (i < 10 ? "dc157_0" + std::to_string(i) + ".dat" : "dc157_10.dat"); }
  static awcc::ProcessOptions options() {
    awcc::ProcessOptions o;
    o.reader.fs = 20e3;
    o.dx = 7.15e-3;
    return o;
  }
};

TEST_F(Spillway, VoidFractionAndCountRateEqualAnIndependentComputation) {
  for (int i = 1; i <= 10; ++i) {
    const auto r = awcc::process_recording(file(i), options());
    EXPECT_EQ(r.info.frames, 900000);
    for (int tip = 0; tip < 2; ++tip) {
      const auto expected = independent(file(i), tip);
      const auto& t = r.tips[static_cast<std::size_t>(tip)];
      EXPECT_NEAR(t.threshold.threshold, expected.threshold, 1e-12) << i << " tip " << tip;
      EXPECT_DOUBLE_EQ(t.phase.void_fraction, expected.void_fraction) << i << " tip " << tip;
      EXPECT_DOUBLE_EQ(t.phase.bubble_count_rate, expected.bubble_count_rate) << i << " tip " << tip;
    }
  }
}

TEST_F(Spillway, VelocitiesArePlausibleAndStableBetweenFullAndSegmented) {
  // A 26.6 degree stepped chute with 0.1 m steps: interfacial velocities of
  // a few m/s. Full-record and Felder's segmented estimates must agree within
  // 5 % (two samples of lag at ~50 samples).
  for (int i = 3; i <= 10; ++i) {
    auto o = options();
    const auto full = awcc::process_recording(file(i), o);
    o.fscc_options.segments = 15;
    o.fscc_options.felder_lags = true;
    const auto segmented = awcc::process_recording(file(i), o);
    ASSERT_TRUE(full.fscc->ok()) << i << ": " << full.fscc->message;
    ASSERT_TRUE(segmented.fscc->ok()) << i << ": " << segmented.fscc->message;
    EXPECT_GT(full.fscc->velocity, 1.0) << i;
    EXPECT_LT(full.fscc->velocity, 6.0) << i;
    EXPECT_NEAR(segmented.fscc->velocity / full.fscc->velocity, 1.0, 0.05) << i;
    EXPECT_GT(full.fscc->r12_max, 0.2) << i;
  }
}

TEST_F(Spillway, FelderRuleSitsHalfABinAboveAndRaisesCAndFByAFewPercent) {
  for (int i = 1; i <= 10; ++i) {
    auto o = options();
    o.fscc = false;
    const auto centre = awcc::process_recording(file(i), o);
    o.binarisation.rule = awcc::ThresholdRule::felder;
    const auto felder = awcc::process_recording(file(i), o);
    for (std::size_t tip = 0; tip < 2; ++tip) {
      EXPECT_NEAR(felder.tips[tip].threshold.threshold - centre.tips[tip].threshold.threshold, 0.05, 1e-9) << i;
      const double dc = felder.tips[tip].phase.void_fraction / centre.tips[tip].phase.void_fraction - 1;
      const double df = felder.tips[tip].phase.bubble_count_rate / centre.tips[tip].phase.bubble_count_rate - 1;
      EXPECT_GT(dc, 0.0) << i;
      EXPECT_LT(dc, 0.04) << i;
      EXPECT_GE(df, 0.0) << i;
      EXPECT_LT(df, 0.04) << i;
    }
  }
}

TEST_F(Spillway, TheProbeCorrectionRaisesTheVelocityByAFewPercentWhereTheFlowIsBubbly) {
  // Files 07-10: C < 0.3, u ~ 3.3 m/s; the needle slows the bubbles by a few
  // per cent (Hohermuth et al. 2021 report 5-10 %, more for small, slow bubbles).
  for (int i = 7; i <= 10; ++i) {
    auto o = options();
    o.fscc = false;
    o.awcc_options.probe_correction.enabled = true;
    const auto r = awcc::process_recording(file(i), o);
    ASSERT_TRUE(r.awcc && r.awcc->ok()) << i;
    ASSERT_TRUE(r.awcc->probe_corrected);
    const double ratio = r.awcc->velocity / r.awcc->velocity_measured;
    EXPECT_GT(ratio, 1.0) << i;
    EXPECT_LT(ratio, 1.15) << i;
    for (const auto& w : r.awcc->windows) {
      if (w.fate != awcc::WindowFate::accepted) continue;
      if (w.void_fraction > 0.3) EXPECT_EQ(w.velocity, w.measured_velocity);
      else EXPECT_GT(w.velocity, w.measured_velocity);
    }
  }
}

TEST_F(Spillway, AwccIntervalAndFftPathsAgreeOnEveryWindow) {
  // Thousands of windows of real data (Np = 5 on the three most aerated
  // files): the two exact paths agree to rounding on every lag.
  std::size_t windows = 0;
  for (int i : {8, 9, 10}) {
    const auto b = awcc::binarise_recording(file(i), options());
    const auto w = awcc::awcc_windows(b.leading, 5);
    awcc::AwccWorkspace plans;
    for (const auto& win : w) {
      const auto a = awcc::detail::window_correlation_intervals(b.leading, b.trailing, win.start, win.length, -(win.length - 1),
                                                        win.length - 1, plans);
      std::vector<double> xs(static_cast<std::size_t>(win.length)), ys(xs.size());
      std::vector<std::uint8_t> d(xs.size());
      b.leading.render(win.start, d);
      std::copy(d.begin(), d.end(), xs.begin());
      b.trailing.render(win.start, d);
      std::copy(d.begin(), d.end(), ys.begin());
      const auto f = awcc::detail::window_correlation_fft(xs, ys, -(win.length - 1), win.length - 1, plans);
      ASSERT_EQ(a.size(), f.size());
      for (std::size_t k = 0; k < a.size(); ++k) ASSERT_NEAR(a[k], f[k], 1e-10) << "file " << i << " lag " << k;
      ++windows;
    }
  }
  EXPECT_GT(windows, 2000u);
}

TEST_F(Spillway, OnePassAndTwoPassBinarisationAgreeExactly) {
  for (int i : {1, 5, 10}) {
    auto o = options();
    const auto one = awcc::binarise_recording(file(i), o);
    o.single_pass = false;
    const auto two = awcc::binarise_recording(file(i), o);
    EXPECT_EQ(one.leading.intervals, two.leading.intervals) << i;
    EXPECT_EQ(one.trailing.intervals, two.trailing.intervals) << i;
    EXPECT_EQ(one.leading_threshold.threshold, two.leading_threshold.threshold) << i;
  }
}

TEST(ProcessSynthetic, OnePassFallsBackWhenTheFirstBlockMisleads) {
  // The first block holds no bubble at all (a long water stretch), so no band
  // can be set from it; and a second recording whose first block has other
  // modes than the whole. Both must equal the two-pass result.
  std::vector<std::int16_t> data;
  for (int i = 0; i < 300000; ++i) {
    const bool air = i > 100000 && (i / 23) % 7 == 0;
    const auto noise = static_cast<int>((static_cast<unsigned>(i) * 7919u) % 61u) - 30;
    data.push_back(static_cast<std::int16_t>((air ? 2000 : 27000) + noise));
    // Trailing: the first block sits at a different water level.
    const bool air2 = (i / 31) % 5 == 0;
    data.push_back(static_cast<std::int16_t>((air2 ? 3000 : (i < 60000 ? 20000 : 27000)) + noise));
  }
  const auto p = pdp_test::temp_dir() / "misleading.dat";
  {
    std::ofstream f(p, std::ios::binary);
    const std::int32_t rows = 300000, channels = 2;
    f.write(reinterpret_cast<const char*>(&rows), 4);
    f.write(reinterpret_cast<const char*>(&channels), 4);
    f.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size() * 2));
  }
  awcc::ProcessOptions o;
  o.reader.fs = 20e3;
  o.block_frames = 50000;
  const auto one = awcc::binarise_recording(p, o);
  o.single_pass = false;
  const auto two = awcc::binarise_recording(p, o);
  EXPECT_EQ(one.leading.intervals, two.leading.intervals);
  EXPECT_EQ(one.trailing.intervals, two.trailing.intervals);
  EXPECT_GT(one.leading.intervals.size(), 100u);
}

TEST(ProcessSynthetic, BinaryScanReadAheadAndTwoPassAgreeWithTheSynthesisedSignals) {
  // A binary W64 (int16 0/1) goes through the two-level scan; its intervals
  // must be the synthesised ones exactly, and equal to the general two-pass
  // path's, with or without the read-ahead thread and for any block size.
  synth::Scene s;
  s.duration = 3.0;
  s.fs = 100e3;
  const auto w = write_scene(s, synth::SignalKind::binary, "binary_scan.w64");
  for (std::int64_t block : {std::int64_t{1} << 18, std::int64_t{777}}) {
    for (bool read_ahead : {true, false}) {
      awcc::ProcessOptions o;
      o.block_frames = block;
      o.read_ahead = read_ahead;
      const auto fast = awcc::binarise_recording(w.path, o);
      EXPECT_EQ(fast.leading.intervals, w.synthesis.signals[0].intervals);
      EXPECT_EQ(fast.trailing.intervals, w.synthesis.signals[1].intervals);
      o.single_pass = false;
      const auto two = awcc::binarise_recording(w.path, o);
      EXPECT_EQ(fast.leading.intervals, two.leading.intervals);
      EXPECT_EQ(fast.trailing.intervals, two.trailing.intervals);
      EXPECT_EQ(fast.leading.sample_count, two.leading.sample_count);
      EXPECT_EQ(fast.leading_threshold.threshold, two.leading_threshold.threshold);
      EXPECT_EQ(fast.leading_threshold.air_level, two.leading_threshold.air_level);
      EXPECT_EQ(fast.trailing_threshold.water_level, two.trailing_threshold.water_level);
      EXPECT_EQ(fast.leading_histogram->values(), two.leading_histogram->values());
      EXPECT_EQ(fast.trailing_histogram->values(), two.trailing_histogram->values());
      EXPECT_TRUE(fast.leading_threshold.binary_input);
    }
  }
}

TEST(ProcessSynthetic, ARecordingThatStopsBeingBinaryIsBinarisedTheGeneralWay) {
  // Two levels for most of the record, then a third value in the trailing tip
  // long after the first block: the scan gives up and the result equals the
  // two-pass path's (a threshold between the modes, not "binary input").
  std::vector<std::int16_t> data;
  for (int i = 0; i < 200000; ++i) {
    const bool air = (i / 37) % 5 == 0;
    data.push_back(static_cast<std::int16_t>(air ? 2000 : 27000));
    const bool air2 = (i / 41) % 4 == 0;
    data.push_back(static_cast<std::int16_t>(i == 150000 ? 14000 : (air2 ? 3000 : 26000)));
  }
  awcc::ProcessOptions o;
  o.block_frames = 10000;
  auto one = awcc::binarise_recording(*awcc::memory_recording(data, 2, 20e3, 5.0 / 32768.0, true), o);
  o.single_pass = false;
  auto two = awcc::binarise_recording(*awcc::memory_recording(data, 2, 20e3, 5.0 / 32768.0, true), o);
  EXPECT_TRUE(one.leading_threshold.binary_input);
  EXPECT_FALSE(one.trailing_threshold.binary_input);
  EXPECT_EQ(one.leading.intervals, two.leading.intervals);
  EXPECT_EQ(one.trailing.intervals, two.trailing.intervals);
  EXPECT_EQ(one.trailing_threshold.threshold, two.trailing_threshold.threshold);
  EXPECT_GT(one.trailing.intervals.size(), 1000u);
}

// --- Bad input and edge cases -----------------------------------------------

std::string process_error(const fs::path& p, const awcc::ProcessOptions& o) {
  try {
    awcc::process_recording(p, o);
  } catch (const std::exception& e) {
    return e.what();
  }
  return {};
}

void write_dat(const fs::path& p, const std::vector<std::int16_t>& interleaved, std::int32_t channels) {
  std::ofstream f(p, std::ios::binary);
  const std::int32_t rows = static_cast<std::int32_t>(interleaved.size()) / channels;
  f.write(reinterpret_cast<const char*>(&rows), 4);
  f.write(reinterpret_cast<const char*>(&channels), 4);
  f.write(reinterpret_cast<const char*>(interleaved.data()), static_cast<std::streamsize>(interleaved.size() * 2));
}

TEST(ProcessInput, ChannelProblemsAreNamed) {
  const auto single = pdp_test::temp_dir() / "single.dat";
  write_dat(single, std::vector<std::int16_t>(1000, 100), 1);
  awcc::ProcessOptions o;
  o.reader.fs = 1000;
  // One channel: not a channel choice to correct but a recording of one tip.
  const std::string one = process_error(single, o);
  EXPECT_NE(one.find("the recording has 1 channel, but pdp processes the tips of a probe together"),
            std::string::npos)
      << one;
  EXPECT_EQ(one.find("within range"), std::string::npos) << one;
  const auto two = pdp_test::temp_dir() / "two.dat";
  write_dat(two, std::vector<std::int16_t>(1000, 100), 2);
  o.trailing_channel = 5;
  EXPECT_NE(process_error(two, o).find("tip 1 is channel 5, but the recording has 2 channels"), std::string::npos)
      << process_error(two, o);
  // A further tip beyond the recording, and one sharing a tip's channel.
  o.trailing_channel = 1;
  o.further_channels = {2};
  EXPECT_NE(process_error(two, o).find("tip 2 is channel 2, but the recording has 2 channels"), std::string::npos)
      << process_error(two, o);
  o.further_channels = {1};
  EXPECT_NE(process_error(two, o).find("tips 1 and 2 are both channel 1"), std::string::npos)
      << process_error(two, o);
}

// A probe of four tips: the further tips are binarised by the same paths as
// the pair (binary 16-bit, one-pass 16-bit, two-pass float), each tip's
// signal equal to the one it gets when it is itself processed as the
// trailing tip of a pair, on every path.
TEST(ProcessInput, FurtherTipsAreBinarisedAsTheTrailingTip) {
  for (const bool binary : {true, false}) {
    const auto path = pdp_test::temp_dir() / (binary ? "four-binary.dat" : "four.dat");
    std::vector<std::int16_t> data;
    for (int i = 0; i < 40000; ++i) {
      for (int tip = 0; tip < 4; ++tip) {
        const bool air = ((i + 13 * tip) / (29 + tip)) % 4 == 0;
        const int jitter = binary ? 0 : (i * (tip + 1)) % 7;
        data.push_back(static_cast<std::int16_t>((air ? 2000 : 27000) + jitter));
      }
    }
    write_dat(path, data, 4);
    for (const bool single_pass : {true, false}) {
      const auto options = [&](int trailing, std::vector<int> further) {
        awcc::ProcessOptions o;
        o.reader.fs = 20000;
        o.single_pass = single_pass;
        o.trailing_channel = trailing;
        o.further_channels = std::move(further);
        return o;
      };
      const auto probe = awcc::binarise_recording(path, options(1, {2, 3}));
      ASSERT_EQ(probe.further_tips.size(), 2u);
      EXPECT_EQ(probe.leading.intervals, awcc::binarise_recording(path, options(1, {})).leading.intervals);
      for (int k = 1; k < 4; ++k) {
        const auto alone = awcc::binarise_recording(path, options(k, {}));
        const auto& got = k == 1 ? probe.trailing : probe.further_tips[static_cast<std::size_t>(k - 2)].signal;
        EXPECT_EQ(got.intervals, alone.trailing.intervals) << "tip " << k << " binary " << binary << " single pass "
                                                           << single_pass;
        EXPECT_FALSE(got.intervals.empty());
        if (k >= 2) {
          const auto& tip = probe.further_tips[static_cast<std::size_t>(k - 2)];
          EXPECT_EQ(tip.channel, k);
          EXPECT_EQ(tip.threshold.lower, alone.trailing_threshold.lower);
          EXPECT_EQ(tip.check.status, alone.trailing_signal.status);
          ASSERT_TRUE(tip.histogram);
          EXPECT_EQ(tip.histogram->total(), 40000);
        }
      }
    }
  }
}

TEST(ProcessInput, AConstantChannelIsRefusedUnlessAllowed) {
  // Leading tip: bubbles; trailing tip: constant, a dead probe or a tip in
  // clear water (the signal check cannot tell): refused, naming the file,
  // the tip and the override. Allowed: c = 0, F = 0, the velocity undefined
  // with its reason, and the failure in the tip's result and the warnings.
  std::vector<std::int16_t> data;
  for (int i = 0; i < 20000; ++i) {
    data.push_back(static_cast<std::int16_t>((i / 37) % 5 == 0 ? 2000 + i % 3 : 27000 + i % 2));
    data.push_back(27000);
  }
  const auto p = pdp_test::temp_dir() / "constant.dat";
  write_dat(p, data, 2);
  awcc::ProcessOptions o;
  o.reader.fs = 20e3;
  o.dx = 5e-3;
  try {
    awcc::process_recording(p, o);
    ADD_FAILURE() << "a constant channel was processed without allow-bad-signal";
  } catch (const awcc::InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(p.string() + ": channel 1 (trailing tip): every sample is 4.12 V", 0), 0u) << what;
    EXPECT_NE(what.find("one level"), std::string::npos) << what;
    EXPECT_EQ(e.quantity(), "allow-bad-signal");
  }
  o.signal_check.allow_bad_signal = true;
  const auto r = awcc::process_recording(p, o);
  EXPECT_EQ(r.tips[0].signal.status, awcc::SignalStatus::two_level);
  EXPECT_EQ(r.tips[1].signal.status, awcc::SignalStatus::one_level);
  EXPECT_TRUE(r.tips[1].signal.overridden);
  ASSERT_EQ(signal_texts(r).size(), 1u);
  EXPECT_EQ(signal_texts(r)[0].rfind("channel 1 (trailing tip): every sample is", 0), 0u) << signal_texts(r)[0];
  EXPECT_NEAR(r.tips[0].phase.void_fraction, 0.2, 0.01);
  EXPECT_EQ(r.tips[1].phase.void_fraction, 0.0);
  EXPECT_EQ(r.tips[1].phase.bubble_count_rate, 0.0);
  ASSERT_TRUE(r.fscc);
  EXPECT_FALSE(r.fscc->ok());
  EXPECT_NE(r.fscc->message.find("constant"), std::string::npos);
  const auto j = awcc::to_json(r);
  EXPECT_TRUE(j["fscc"]["velocity"].is_null());
  EXPECT_FALSE(j["fscc"]["reason"].is_null());
}


// The one way from binary signals in memory to a recording (what studies and
// the multi-tip validation process): for a four-tip scene it equals what
// binarise_recording reads from the binary file written from the same
// signals, tip by tip (signal, threshold, histogram, signal check), and a
// dead tip is refused with the file's message unless allowed.
TEST(ProcessInput, BinarySignalsInMemoryAreTheRecordingOfTheirFile) {
  synth::Scene s;
  s.duration = 1.5;
  s.tips = {{0.0, 0.0, 0.0}, {5e-3, 0.0, 0.0}, {4e-3, 1e-3, 0.0}, {4e-3, 0.0, 1e-3}};
  const auto w = write_scene(s, synth::SignalKind::binary, "in_memory_four.flac");
  awcc::ProcessOptions o;
  o.trailing_channel = 1;
  o.further_channels = {2, 3};
  const auto file = awcc::binarise_recording(w.path, o);
  const auto memory = awcc::binary_recording(w.synthesis.signals, o);
  ASSERT_EQ(memory.further_tips.size(), 2u);
  EXPECT_EQ(memory.info.fs, file.info.fs);
  EXPECT_EQ(memory.info.frames, file.info.frames);
  EXPECT_EQ(memory.leading.intervals, file.leading.intervals);
  EXPECT_EQ(memory.trailing.intervals, file.trailing.intervals);
  // The levels' scale differs (0 and 1 in memory, 0 and one count in the
  // file), so the thresholds' values do; both are binary input, not applied.
  EXPECT_TRUE(memory.leading_threshold.binary_input && file.leading_threshold.binary_input);
  EXPECT_TRUE(memory.trailing_threshold.binary_input && file.trailing_threshold.binary_input);
  EXPECT_EQ(memory.leading_signal.status, awcc::SignalStatus::binary_input);
  EXPECT_EQ(memory.leading_signal.status, file.leading_signal.status);
  EXPECT_EQ(memory.trailing_signal.air_share, file.trailing_signal.air_share);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& m = memory.further_tips[k];
    const auto& f = file.further_tips[k];
    EXPECT_EQ(m.channel, f.channel);
    EXPECT_EQ(m.signal.intervals, f.signal.intervals);
    EXPECT_TRUE(m.threshold.binary_input && f.threshold.binary_input);
    // A further tip gets the check too (the multi-tip validation's did not).
    EXPECT_EQ(m.check.status, f.check.status) << "tip " << k + 2;
    EXPECT_EQ(m.check.air_share, f.check.air_share);
    ASSERT_TRUE(m.histogram && f.histogram);
    EXPECT_EQ(m.histogram->total(), f.histogram->total());
  }

  // A dead fourth tip (all water): refused naming its channel, as a file's.
  auto dead = w.synthesis.signals;
  dead[3] = pdp_test::all_water_like(dead[3]);
  try {
    (void)awcc::binary_recording(dead, o);
    ADD_FAILURE() << "a dead tip in memory was accepted without allow-bad-signal";
  } catch (const awcc::InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("binary signals in memory: channel 3 (tip 3): ", 0), 0u) << what;
    EXPECT_EQ(e.quantity(), "allow-bad-signal");
  }
  o.signal_check.allow_bad_signal = true;
  const auto allowed = awcc::binary_recording(dead, o);
  EXPECT_EQ(allowed.further_tips[1].check.status, awcc::SignalStatus::one_level);
  EXPECT_TRUE(allowed.further_tips[1].check.overridden);
  // Processed as a probe, the dead tip's failure is in the warnings (every
  // output's list), as a pair's tip's is (issue 53: the JSON's were empty).
  awcc::ProcessOptions probe = o;
  probe.further_channels.clear();
  for (const auto& t : s.tips) probe.probe.positions.push_back({t.x, t.y, t.z});
  probe.multi_tip = awcc::MultiTipChoice::on;
  awcc::RecordingInfo info = allowed.info;
  const auto resolved = awcc::tip_pair_options(probe, info);
  std::vector<awcc::Vec3> positions;
  for (const int c : resolved.tip_channels()) {
    const auto& t = s.tips.at(static_cast<std::size_t>(c));
    positions.push_back({t.x, t.y, t.z});
  }
  const auto r = awcc::process_binarised(
      awcc::binary_recording(dead, resolved, resolved.tip_channels(), std::move(positions)), resolved);
  ASSERT_TRUE(r.probe);
  EXPECT_TRUE(std::any_of(r.warnings.begin(), r.warnings.end(), [](const awcc::Warning& warning) {
    return warning.flag == awcc::Flag::signal_check && warning.text.rfind("channel 3 (tip 3): ", 0) == 0 &&
           warning.text.find("allow-bad-signal") != std::string::npos;
  })) << (r.warnings.empty() ? std::string("no warning") : r.warnings.front().text);
}


// A channel copied in the acquisition (issue 53): two tips holding the same
// signal are refused naming both channels, for a tip pair and for a
// further tip of a probe; allowed, the row is flagged channels_copied. A
// near copy (a few samples differ, r above copied_channel_correlation) is
// flagged, not refused; tips a sample apart are neither.
TEST(ProcessInput, ACopiedChannelIsRefusedNamingBothTips) {
  const auto path = pdp_test::temp_dir() / "copied.dat";
  auto level = [](int i, int tip) {
    const int shift = tip == 3 ? 1 : tip;  // tip 3 copies tip 1
    return ((i + 13 * shift) / (29 + shift)) % 4 == 0;
  };
  std::vector<std::int16_t> data;
  for (int i = 0; i < 40000; ++i) {
    for (int tip = 0; tip < 4; ++tip) data.push_back(static_cast<std::int16_t>(level(i, tip) ? 2000 : 27000));
  }
  write_dat(path, data, 4);
  awcc::ProcessOptions o;
  o.reader.fs = 20000;
  o.dx = 5e-3;
  o.further_channels = {2, 3};
  const std::string refused = process_error(path, o);
  EXPECT_NE(refused.find("channel 3 (tip 3) holds the same signal as channel 1 (trailing tip)"), std::string::npos)
      << refused;
  EXPECT_NE(refused.find("allow a bad signal"), std::string::npos) << refused;
  // The pair alone: trailing tip 3 copies the leading... here tip 1 and 3 as the pair.
  o.further_channels.clear();
  o.leading_channel = 1;
  o.trailing_channel = 3;
  EXPECT_NE(process_error(path, o).find("channel 3 (trailing tip) holds the same signal as channel 1 (leading tip)"),
            std::string::npos)
      << process_error(path, o);
  // Allowed: processed, flagged in every output's list.
  o.signal_check.allow_bad_signal = true;
  const auto r = awcc::process_recording(path, o);
  ASSERT_EQ(r.channel_copies.size(), 1u);
  EXPECT_TRUE(r.channel_copies[0].identical);
  EXPECT_DOUBLE_EQ(r.channel_copies[0].correlation, 1.0);
  EXPECT_TRUE(std::any_of(r.warnings.begin(), r.warnings.end(),
                          [](const awcc::Warning& w) { return w.flag == awcc::Flag::channels_copied; }));
  // Distinct tips (channels 0 and 1: other bubbles) are not a copy.
  o.leading_channel = 0;
  o.trailing_channel = 1;
  o.signal_check.allow_bad_signal = false;
  EXPECT_TRUE(awcc::process_recording(path, o).channel_copies.empty());
}

TEST(ProcessInput, ANearCopyIsFlaggedAndTipsASampleApartAreNot) {
  // A signal of chords of 2,000 samples, half air: its copy with one chord
  // a sample longer (r = 0.99998) is a near copy; the same signal two
  // samples later differs by 4 samples a chord pair, r = 1 - 4 / 2000 =
  // 0.998: two tips.
  const auto x = pdp_test::square_wave(400'000, 2000, 2000, 20e3);
  auto near = x;
  near.intervals[10].stop += 1;
  for (const auto& [trailing, copied] : {std::pair{near, true}, std::pair{pdp_test::shifted(x, 2), false}}) {
    awcc::ProcessOptions o;
    o.dx = 5e-3;
    o.signal_check.allow_bad_signal = false;
    const auto rec = awcc::binary_recording({x, trailing}, o);
    EXPECT_EQ(rec.copies.size(), copied ? 1u : 0u);
    if (copied) {
      EXPECT_FALSE(rec.copies[0].identical);
      EXPECT_GT(rec.copies[0].correlation, awcc::copied_channel_correlation);
    }
  }
}

}  // namespace
