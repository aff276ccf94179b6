// The signal check (awcc/signal_check.hpp): its decision thresholds at and
// around their limits on histograms built count by count, then whole
// recordings: the ten real ones pass unchanged, and noise, a dead, a clipped
// and a drifting channel, inverted polarity and spray-like recordings (made
// from the real and synthetic ones) get what the header promises.
#include "awcc/signal_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>

#include "awcc/errors.hpp"
#include "awcc/process.hpp"
#include "synth/recording.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"
#include "result_warnings.hpp"

namespace {

using pdp_test::signal_texts;


using awcc::SignalStatus;
constexpr double kQuantum = 5.0 / 32768.0;  // a UQ .dat count

// A histogram of counts: (count, samples) pairs.
awcc::VoltageHistogram counts(std::initializer_list<std::pair<int, std::int64_t>> entries) {
  awcc::VoltageHistogram h(kQuantum);
  for (const auto& [count, n] : entries) {
    const std::int64_t one[1] = {n};
    h.add_counts(one, count);
  }
  return h;
}

// `n` samples spread evenly over the 2000 counts from `from`: a side's
// samples that are no level (each 100-bin bin holds few of them).
void spread(awcc::VoltageHistogram& h, int from, int n) {
  for (int k = 0; k < n; ++k) {
    const std::int64_t one[1] = {1};
    h.add_counts(one, from + k % 2000);
  }
}

awcc::SignalCheck check(const awcc::VoltageHistogram& h, awcc::ProbeType probe = awcc::ProbeType::conductivity,
                        const awcc::SignalCheckOptions& o = {}) {
  return awcc::check_signal(h, probe, awcc::int16_limits(kQuantum), o);
}

// Levels at counts 1000 and 9000 (the range's ends: the 100-bin modes of
// 80 counts are centred on them, D / 8 = 1000 counts), `low` and `high`
// samples there, and `low_spread` samples over counts 2500-4499,
// `high_spread` over 5500-7499: on their level's side of the midpoint (5000),
// 1500 counts or more from it.
awcc::VoltageHistogram levels(std::int64_t low, int low_spread, std::int64_t high, int high_spread) {
  auto h = counts({{1000, low}, {9000, high}});
  spread(h, 2500, low_spread);
  spread(h, 5500, high_spread);
  return h;
}

TEST(SignalCheck, FlatnessAtItsLimit) {
  // Flatness of a side = its level's samples / its samples. High side 6000 /
  // (6000 + 4000) = 0.6 exactly passes; 5999 / 10000 fails. The low side is
  // kept less flat (3000 / 10000).
  const auto at = check(levels(3000, 7000, 6000, 4000));
  EXPECT_EQ(at.status, SignalStatus::two_level) << at.message;
  EXPECT_DOUBLE_EQ(at.flatness, 0.6);
  EXPECT_NEAR(at.low_level, 1000 * kQuantum, 1e-9);
  EXPECT_NEAR(at.high_level, 9000 * kQuantum, 1e-9);
  const auto below = check(levels(3000, 7000, 5999, 4001));
  EXPECT_EQ(below.status, SignalStatus::no_flat_level);
  EXPECT_NE(below.message.find("no flat level"), std::string::npos) << below.message;
  EXPECT_NE(below.message.find("60 %"), std::string::npos) << below.message;
  // The flatter side decides: the same with the sides exchanged.
  EXPECT_EQ(check(levels(6000, 4000, 3000, 7000)).status, SignalStatus::two_level);
}

TEST(SignalCheck, SecondLevelShareAtItsLimit) {
  // 100 of 1,000,000 samples at the far level: a share of 1e-4 exactly passes;
  // 99 is one level (a glitch or two on a dead channel). A third value (8990
  // counts, on the high side) keeps it from being binary input.
  const auto at = check(counts({{1000, 100}, {8990, 1}, {9000, 999899}}));
  EXPECT_EQ(at.status, SignalStatus::two_level) << at.message;
  EXPECT_DOUBLE_EQ(at.minor_share, 1e-4);
  const auto below = check(counts({{1000, 99}, {8990, 1}, {9000, 999900}}));
  EXPECT_EQ(below.status, SignalStatus::one_level);
  EXPECT_NE(below.message.find("one level (1.373 V)"), std::string::npos) << below.message;
}

TEST(SignalCheck, SeparationAtItsLimit) {
  // Levels 16 and 15 counts apart (a third value keeps it from being binary
  // input): at least 16 resolution steps. At the limit the comparison is
  // tested with the limit set to the measured separation and just above it.
  const auto sixteen = counts({{1000, 5000}, {1008, 1}, {1016, 5000}});
  const auto r = check(sixteen);
  EXPECT_EQ(r.status, SignalStatus::two_level) << r.message;
  const double steps = (r.high_level - r.low_level) / kQuantum;
  EXPECT_NEAR(steps, 16.0, 1e-6);
  awcc::SignalCheckOptions o;
  o.min_separation_counts = steps;
  EXPECT_EQ(check(sixteen, awcc::ProbeType::conductivity, o).status, SignalStatus::two_level);
  o.min_separation_counts = std::nextafter(steps, 100.0);
  EXPECT_EQ(check(sixteen, awcc::ProbeType::conductivity, o).status, SignalStatus::one_level);
  const auto fifteen = check(counts({{1000, 5000}, {1008, 1}, {1015, 5000}}));
  EXPECT_EQ(fifteen.status, SignalStatus::one_level);
  EXPECT_NE(fifteen.message.find("15 steps of the data's resolution"), std::string::npos) << fifteen.message;
}

TEST(SignalCheck, RailShareAtItsLimit) {
  // A two-level signal whose high level holds 1 % of the samples at the
  // limit (32767 counts) and the rest 30 counts below: 1 % is clipped, 0.99 %
  // is not. -32768 counts lies beyond the low limit and counts too.
  const auto at = check(counts({{2000, 20000}, {32737, 79000}, {32767, 1000}}));
  EXPECT_EQ(at.status, SignalStatus::saturated);
  EXPECT_DOUBLE_EQ(at.rail_share, 0.01);
  EXPECT_NE(at.message.find("1 % of the samples sit at the digitiser's limit (+5 V)"), std::string::npos) << at.message;
  EXPECT_EQ(check(counts({{2000, 20000}, {32737, 79010}, {32767, 990}})).status, SignalStatus::two_level);
  EXPECT_EQ(check(counts({{-32768, 1000}, {-32700, 19000}, {30000, 80000}})).status, SignalStatus::saturated);
  // Limits unknown (floating data): not tested.
  EXPECT_EQ(awcc::check_signal(counts({{2000, 20000}, {32737, 79000}, {32767, 1000}}), awcc::ProbeType::conductivity,
                               std::nullopt)
                .status,
            SignalStatus::two_level);
  // A channel stuck at the limit.
  EXPECT_EQ(check(counts({{32767, 5000}})).status, SignalStatus::saturated);
}

TEST(SignalCheck, DeadChannels) {
  // Constant: one level.
  const auto constant = check(counts({{27000, 50000}}));
  EXPECT_EQ(constant.status, SignalStatus::one_level);
  EXPECT_NE(constant.message.find("every sample is 4.12 V"), std::string::npos) << constant.message;
  // +/- 1 count of noise: the modes 1-2 counts apart.
  std::mt19937 rng(3);
  awcc::VoltageHistogram flicker(kQuantum);
  for (int i = 0; i < 100000; ++i) {
    const std::int64_t one[1] = {1};
    flicker.add_counts(one, 27000 + static_cast<int>(rng() % 3) - 1);
  }
  EXPECT_EQ(check(flicker).status, SignalStatus::one_level);
  // Two values within one step of a floating histogram's resolution (0.1 mV).
  awcc::VoltageHistogram fine(1e-4);
  const float v[4] = {1.00001f, 1.00002f, 1.00001f, 1.00002f};
  fine.add(v, 0, 1);
  EXPECT_EQ(awcc::check_signal(fine, awcc::ProbeType::conductivity, std::nullopt).status, SignalStatus::one_level);
}

TEST(SignalCheck, NoiseHumAndUniformHaveNoFlatLevel) {
  // The header's measurements: Gaussian noise (its two modes within a
  // fraction of a standard deviation), a 50 Hz sine (arcsine: 47 % within
  // D / 8 of its extremes) and uniform noise all stay below 60 %. Uniform
  // noise over R has its modes where the counts happen to peak: a side R / 2
  // wide keeps at most (D / 4) / (R / 2) <= 1/2 within D / 8 of its mode.
  std::mt19937 rng(1);
  std::normal_distribution<double> gauss(0.0, 6000.0);
  std::uniform_real_distribution<double> uniform(0.0, 26000.0);
  awcc::VoltageHistogram noise(kQuantum), hum(kQuantum), flat(kQuantum);
  for (int i = 0; i < 900000; ++i) {
    const std::int64_t one[1] = {1};
    noise.add_counts(one, static_cast<std::int64_t>(std::lround(gauss(rng))));
    hum.add_counts(one, static_cast<std::int64_t>(std::lround(13000.0 + 6500.0 * std::sin(2.0 * std::numbers::pi * 50.0 * i / 20e3))));
    flat.add_counts(one, static_cast<std::int64_t>(std::lround(uniform(rng))));
  }
  const auto n = check(noise), s = check(hum), u = check(flat);
  EXPECT_EQ(n.status, SignalStatus::no_flat_level);
  EXPECT_LT(n.flatness, 0.2);
  EXPECT_EQ(s.status, SignalStatus::no_flat_level);
  EXPECT_NEAR(s.flatness, 0.47, 0.02);
  EXPECT_EQ(u.status, SignalStatus::no_flat_level);
  EXPECT_LE(u.flatness, 0.5);
}

TEST(SignalCheck, PolarityCuesAtTheirLimits) {
  // Air (the low level, conductivity) holding 70 % of the samples is still
  // the intermediate regime; 70 % and one sample more is the droplet one:
  // flagged, not refused, while the levels are positive (the low one nearer
  // 0 V, as a conductivity probe's air level is).
  const auto seventy = check(counts({{8000, 70000}, {26900, 1}, {27000, 29999}}));
  EXPECT_EQ(seventy.status, SignalStatus::two_level) << seventy.message;
  const auto more = check(counts({{8000, 70001}, {26900, 1}, {27000, 29998}}));
  EXPECT_EQ(more.status, SignalStatus::air_continuous);
  EXPECT_FALSE(more.failed());
  EXPECT_NE(more.message.find("state probe = optical"), std::string::npos) << more.message;
  // Negative levels: the low one, air by probe, lies farther from 0 V than the
  // high one. Both cues: inverted polarity, refused. At the ratio's limit
  // (2) the bin centres of the 100-bin modes decide, so the limit is set to
  // the measured ratio and just above it.
  const auto negated = counts({{-27000, 96000}, {-20000, 1}, {-8000, 3999}});
  const auto inverted = check(negated);
  EXPECT_EQ(inverted.status, SignalStatus::inverted_polarity);
  EXPECT_TRUE(inverted.failed());
  EXPECT_NE(inverted.message.find("the polarity contradicts probe = conductivity"), std::string::npos)
      << inverted.message;
  const double ratio = inverted.low_level / inverted.high_level;
  EXPECT_NEAR(ratio, 27000.0 / 8000.0, 0.05);
  awcc::SignalCheckOptions o;
  o.zero_level_ratio = ratio;
  EXPECT_EQ(check(negated, awcc::ProbeType::conductivity, o).status, SignalStatus::inverted_polarity);
  o.zero_level_ratio = std::nextafter(ratio, 10.0);
  EXPECT_EQ(check(negated, awcc::ProbeType::conductivity, o).status, SignalStatus::air_continuous);
  // Stated as optical (air the high level), the same recording is a bubbly one.
  const auto optical = check(negated, awcc::ProbeType::optical);
  EXPECT_EQ(optical.status, SignalStatus::two_level) << optical.message;
  EXPECT_NEAR(optical.air_share, 0.04, 1e-4);
  // Levels on both sides of 0 V: the zero-level cue says nothing; flagged only.
  EXPECT_EQ(check(counts({{-20000, 96000}, {-1000, 1}, {8000, 3999}})).status, SignalStatus::air_continuous);
}

TEST(SignalCheck, BinaryInputIsNotCheckedButItsPolarityIs) {
  const auto bubbly = check(counts({{0, 75000}, {1, 25000}}));
  EXPECT_EQ(bubbly.status, SignalStatus::binary_input);
  EXPECT_TRUE(bubbly.message.empty());
  const auto spray = check(counts({{0, 25000}, {1, 75000}}));
  EXPECT_EQ(spray.status, SignalStatus::air_continuous);
  EXPECT_DOUBLE_EQ(spray.air_share, 0.75);
}

// --- Whole recordings ---------------------------------------------------------

std::filesystem::path spillway(int i) {
  return pdp_test::source_dir().parent_path() / "shared" / "data" / "felder-stepped-spillway" /
         (i < 10 ? "dc157_0" + std::to_string(i) + ".dat" : "dc157_10.dat");
}

// A UQ .dat's counts (interleaved, two channels).
std::vector<std::int16_t> dat_counts(const std::filesystem::path& p) {
  auto r = awcc::open_recording(p, [] {
    awcc::ReaderOptions o;
    o.fs = 20e3;
    return o;
  }());
  std::vector<std::int16_t> out(static_cast<std::size_t>(r->info().frames * r->info().channels));
  r->read_int16(out, r->info().frames);
  return out;
}

awcc::ProcessOptions real_options() {
  awcc::ProcessOptions o;
  o.reader.fs = 20e3;
  o.dx = 7.15e-3;
  o.awcc = false;  // the signal check runs before any method
  o.fscc = false;
  return o;
}

awcc::ProcessResult process_counts(std::vector<std::int16_t> data, awcc::ProcessOptions o, double fs = 20e3,
                                   double quantum = kQuantum) {
  auto rec = awcc::memory_recording(std::move(data), 2, fs, quantum, true, "test.dat");
  return awcc::process_recording(*rec, o);
}

// The error of processing, or empty.
std::string refusal(std::vector<std::int16_t> data, const awcc::ProcessOptions& o, std::string* quantity = nullptr) {
  try {
    process_counts(std::move(data), o);
  } catch (const awcc::InputError& e) {
    if (quantity) *quantity = e.quantity();
    return e.what();
  }
  return {};
}

class RealRecordings : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(spillway(1))) {
      GTEST_SKIP() << "the real recordings are not here: " << spillway(1).parent_path();
    }
  }
};

TEST_F(RealRecordings, AllTenPassWithoutAWordAndTheirNumbersUnchanged) {
  for (int i = 1; i <= 10; ++i) {
    auto o = real_options();
    const auto r = awcc::process_recording(spillway(i), o);
    EXPECT_TRUE(signal_texts(r).empty()) << i << ": " << signal_texts(r).front();
    for (const auto& t : r.tips) {
      EXPECT_EQ(t.signal.status, SignalStatus::two_level) << i << ": " << t.signal.message;
      EXPECT_GE(t.signal.flatness, 0.98) << i;         // header: 0.980-0.998
      EXPECT_GE(t.signal.minor_share, 0.0036) << i;   // header: at least 0.36 %
      EXPECT_EQ(t.signal.rail_share, 0.0) << i;
    }
    // The check only reads: the binarisation is the one without it.
    o.signal_check.allow_bad_signal = true;
    const auto same = awcc::process_recording(spillway(i), o);
    EXPECT_EQ(same.tips[0].phase.void_fraction, r.tips[0].phase.void_fraction);
    EXPECT_EQ(same.tips[1].phase.bubble_count_rate, r.tips[1].phase.bubble_count_rate);
  }
}

TEST_F(RealRecordings, InvertedSignRefusedMirroredFlaggedOpticalAccepted) {
  const auto data = dat_counts(spillway(5));
  const auto base = process_counts(data, real_options());
  // Sign inverted: both cues, refused naming the tip, the cause and both fixes.
  std::vector<std::int16_t> negated(data.size()), mirrored(data.size());
  for (std::size_t k = 0; k < data.size(); ++k) {
    negated[k] = static_cast<std::int16_t>(-data[k]);
    mirrored[k] = static_cast<std::int16_t>(32767 - data[k]);
  }
  std::string quantity;
  const auto why = refusal(negated, real_options(), &quantity);
  EXPECT_EQ(why.rfind("test.dat: channel 0 (leading tip): the polarity contradicts probe = conductivity", 0), 0u) << why;
  EXPECT_NE(why.find("holds 96.2 % of the samples"), std::string::npos) << why;
  EXPECT_NE(why.find("channel 1 (trailing tip) likewise"), std::string::npos) << why;
  EXPECT_EQ(quantity, "probe,allow-bad-signal");
  // Stated optical, the inverted recording is the bubbly one again (c within
  // a histogram bin's worth of samples of the original's).
  auto optical = real_options();
  optical.binarisation.probe = awcc::ProbeType::optical;
  const auto back = process_counts(negated, optical);
  EXPECT_TRUE(signal_texts(back).empty());
  EXPECT_NEAR(back.tips[0].phase.void_fraction, base.tips[0].phase.void_fraction, 2e-3);
  // Allowed as stated: processed, c = 0.96, the failure in the result and the warnings.
  auto allowed = real_options();
  allowed.signal_check.allow_bad_signal = true;
  const auto forced = process_counts(negated, allowed);
  EXPECT_GT(forced.tips[0].phase.void_fraction, 0.95);
  EXPECT_TRUE(forced.tips[0].signal.overridden);
  EXPECT_EQ(forced.tips[0].signal.status, SignalStatus::inverted_polarity);
  ASSERT_EQ(signal_texts(forced).size(), 2u);
  EXPECT_NE(signal_texts(forced)[0].find("processed anyway, as allow-bad-signal asks"), std::string::npos);
  // Mirrored within the range (levels stay positive, air the majority): a
  // spray region looks exactly so; flagged in the warnings, not refused.
  const auto spray = process_counts(mirrored, real_options());
  EXPECT_EQ(spray.tips[0].signal.status, SignalStatus::air_continuous);
  EXPECT_FALSE(spray.tips[0].signal.overridden);
  ASSERT_EQ(signal_texts(spray).size(), 2u);
  EXPECT_EQ(signal_texts(spray)[0].rfind("channel 0 (leading tip): the low level", 0), 0u) << signal_texts(spray)[0];
  EXPECT_NE(signal_texts(spray)[0].find("spray region"), std::string::npos);
  EXPECT_GT(spray.tips[0].phase.void_fraction, 0.95);
}

TEST_F(RealRecordings, ClippingAndDriftAsTheHeaderMeasures) {
  const auto data = dat_counts(spillway(5));
  // Gain x 1.25: the water level clipped at 32767 counts.
  std::vector<std::int16_t> clipped(data.size());
  for (std::size_t k = 0; k < data.size(); ++k) {
    clipped[k] = static_cast<std::int16_t>(std::clamp(std::lround(1.25 * data[k]), -32768L, 32767L));
  }
  const auto why = refusal(clipped, real_options());
  EXPECT_NE(why.find("channel 0 (leading tip): 95.2 % of the samples sit at the digitiser's limit"), std::string::npos)
      << why;
  // A linear drift of both levels over the record: 0.8 V (0.3 D) passes, 1.2 V (0.4 D) has no flat level.
  auto drift = [&](double volts) {
    std::vector<std::int16_t> out(data.size());
    const std::size_t frames = data.size() / 2;
    for (std::size_t k = 0; k < data.size(); ++k) {
      const double ramp = (static_cast<double>(k / 2) / static_cast<double>(frames - 1) - 0.5) * volts / kQuantum;
      out[k] = static_cast<std::int16_t>(std::clamp(std::lround(data[k] + ramp), -32768L, 32767L));
    }
    return out;
  };
  const auto slow = process_counts(drift(0.8), real_options());
  EXPECT_EQ(slow.tips[0].signal.status, SignalStatus::two_level);
  EXPECT_NEAR(slow.tips[0].signal.flatness, 0.645, 0.005);
  const auto fast = refusal(drift(1.2), real_options());
  EXPECT_NE(fast.find("channel 0 (leading tip): the voltage histogram has no flat level"), std::string::npos) << fast;
}

TEST(SignalCheckRecordings, NoiseIsRefusedAndAllowedWithTheFlag) {
  // Issue 29 case 2: Gaussian noise read as flow (c 0.38 and 0.54, AWCC 74 m/s).
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss(0.0, 6000.0);
  std::vector<std::int16_t> noise(2 * 200000);
  for (auto& v : noise) v = static_cast<std::int16_t>(std::clamp(std::lround(gauss(rng)), -32768L, 32767L));
  std::string quantity;
  const auto why = refusal(noise, real_options(), &quantity);
  EXPECT_EQ(why.rfind("test.dat: channel 0 (leading tip): the voltage histogram has no flat level", 0), 0u) << why;
  EXPECT_NE(why.find("allow a bad signal"), std::string::npos) << why;
  EXPECT_EQ(quantity, "allow-bad-signal");
  auto o = real_options();
  o.signal_check.allow_bad_signal = true;
  const auto r = process_counts(noise, o);
  for (const auto& t : r.tips) {
    EXPECT_EQ(t.signal.status, SignalStatus::no_flat_level);
    EXPECT_TRUE(t.signal.overridden);
  }
  EXPECT_EQ(signal_texts(r).size(), 2u);
}

TEST(SignalCheckRecordings, SyntheticVoltageFromLowToHighVoidFractionPasses) {
  // pdp synth --signal voltage at c = 0.005 to 0.6 (measured up to 0.54:
  // overlapping bubbles): two levels, no flag. Its mirror within the levels
  // (air continuous: c about 0.95 at c = 0.05) is flagged, its sign
  // inversion refused.
  for (double c : {0.005, 0.05, 0.25, 0.6}) {
    synth::Scene s;
    s.void_fraction = c;
    s.duration = 2.0;
    const auto synthesis = synth::synthesise(s);
    std::vector<std::vector<std::uint8_t>> dense;
    for (const auto& signal : synthesis.signals) dense.push_back(awcc::to_dense(signal));
    synth::VoltageRenderer renderer(s, 2);
    std::vector<std::int16_t> data(2 * dense[0].size());
    renderer.render({dense[0], dense[1]}, data);
    const auto r = process_counts(data, real_options(), s.fs, renderer.volts_per_count());
    for (std::size_t j = 0; j < 2; ++j) {
      EXPECT_EQ(r.tips[j].signal.status, SignalStatus::two_level) << c << ": " << r.tips[j].signal.message;
      EXPECT_NEAR(r.tips[j].phase.void_fraction, synthesis.truth.tips[j].void_fraction, 1e-3) << c;
    }
    EXPECT_TRUE(signal_texts(r).empty()) << c;
    if (c != 0.05) continue;
    // Mirror within the levels: counts a + b - v keep the levels where they are.
    const auto water = static_cast<int>(std::lround(s.voltage_water / renderer.volts_per_count()));
    const auto air = static_cast<int>(std::lround(s.voltage_air / renderer.volts_per_count()));
    std::vector<std::int16_t> spray(data.size()), negated(data.size());
    for (std::size_t k = 0; k < data.size(); ++k) {
      spray[k] = static_cast<std::int16_t>(water + air - data[k]);
      negated[k] = static_cast<std::int16_t>(-data[k]);
    }
    const auto flagged = process_counts(spray, real_options(), s.fs, renderer.volts_per_count());
    EXPECT_EQ(flagged.tips[0].signal.status, SignalStatus::air_continuous);
    EXPECT_NEAR(flagged.tips[0].phase.void_fraction, 1.0 - synthesis.truth.tips[0].void_fraction, 1e-3);
    EXPECT_EQ(signal_texts(flagged).size(), 2u);
    EXPECT_THROW(process_counts(negated, real_options(), s.fs, renderer.volts_per_count()), awcc::InputError);
  }
}

}  // namespace
