#include "awcc/binarisation.hpp"

#include <gtest/gtest.h>

#include <random>

namespace {

using awcc::BinarisationOptions;
using awcc::ThresholdRule;
using awcc::VoltageHistogram;

// A conductivity-like signal in counts of 5/32768 V: water near 4.15 V, air
// near 1.35 V, a few samples in between.
std::vector<float> two_level_signal(std::vector<std::uint8_t>& truth) {
  const double vpc = 5.0 / 32768.0;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<float> v;
  std::uint8_t air = 0;
  for (int i = 0; i < 20000; ++i) {
    if (rng() % 40 == 0) air ^= 1;
    truth.push_back(air);
    const double level = air ? 1.35 : 4.15;
    const auto counts = std::nearbyint((level + noise(rng)) / vpc);
    v.push_back(static_cast<float>(counts * vpc));
  }
  return v;
}

TEST(Threshold, HistogramRuleUsesBinCentresAndTheta) {
  std::vector<std::uint8_t> truth;
  const auto v = two_level_signal(truth);
  VoltageHistogram h(5.0 / 32768.0);
  h.add(v, 0, 1);
  EXPECT_EQ(h.total(), 20000);
  BinarisationOptions o;
  const auto t = awcc::choose_threshold(h, o);
  // Modes in bins [1.3, 1.4) and [4.1, 4.2): centres 1.35 and 4.15.
  EXPECT_NEAR(t.air_level, 1.35, 1e-12);
  EXPECT_NEAR(t.water_level, 4.15, 1e-12);
  EXPECT_NEAR(t.threshold, 2.75, 1e-12);
  o.theta = 0.25;
  EXPECT_NEAR(awcc::choose_threshold(h, o).threshold, 1.35 + 0.25 * 2.8, 1e-12);
  // Felder labels bins by their upper edge: 1.4 and 4.2, threshold 2.8 = 2.75 + 0.05.
  o.theta = 0.5;
  o.rule = ThresholdRule::felder;
  const auto f = awcc::choose_threshold(h, o);
  EXPECT_NEAR(f.threshold, 2.8, 1e-12);
  EXPECT_NEAR(f.tolerance, 1e-5, 0.0);
}

TEST(Threshold, OpticalProbeSwapsTheModes) {
  std::vector<std::uint8_t> truth;
  const auto v = two_level_signal(truth);
  VoltageHistogram h(5.0 / 32768.0);
  h.add(v, 0, 1);
  BinarisationOptions o;
  o.probe = awcc::ProbeType::optical;
  const auto t = awcc::choose_threshold(h, o);
  EXPECT_NEAR(t.air_level, 4.15, 1e-12);
  EXPECT_NEAR(t.water_level, 1.35, 1e-12);
  // Binarised as optical, the air fraction is the complement.
  awcc::Binariser b(t, 1000.0);
  b.feed(v, 0, 1);
  const auto s = b.finish();
  std::int64_t water = 0;
  for (auto x : truth) water += 1 - x;
  EXPECT_EQ(s.air_samples(), water);
}

TEST(Binariser, RecoversTheTwoLevelsAcrossBlocksAndStrides) {
  std::vector<std::uint8_t> truth;
  const auto v = two_level_signal(truth);
  VoltageHistogram h(5.0 / 32768.0);
  h.add(v, 0, 1);
  const auto t = awcc::choose_threshold(h, {});
  // Interleave with a dummy channel and feed in uneven blocks.
  std::vector<float> two(2 * v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    two[2 * i] = -1.0f;
    two[2 * i + 1] = v[i];
  }
  awcc::Binariser b(t, 1000.0);
  std::size_t pos = 0;
  for (std::size_t block : {1u, 333u, 5000u, 100000u}) {
    const std::size_t n = std::min(block, v.size() - pos);
    b.feed(std::span<const float>(two.data() + 2 * pos, 2 * n), 1, 2);
    pos += n;
  }
  const auto s = b.finish();
  EXPECT_EQ(s.sample_count, 20000);
  EXPECT_TRUE(s.check().empty());
  EXPECT_EQ(awcc::to_dense(s), truth);
}

TEST(Binariser, HysteresisSuppressesChatterThatASingleThresholdCounts) {
  // A slow ramp from water to air with noise larger than the step per
  // sample: a single threshold chatters, hysteresis switches once.
  std::vector<float> v;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int i = 0; i < 2000; ++i) v.push_back(static_cast<float>(4.0 - 3.0 * i / 1999.0 + noise(rng)));
  for (int i = 0; i < 500; ++i) v.push_back(static_cast<float>(1.0 + noise(rng)));
  for (int i = 0; i < 500; ++i) v.push_back(static_cast<float>(4.0 + noise(rng)));
  awcc::Threshold single;
  single.threshold = single.lower = single.upper = 2.5;
  awcc::Threshold hyst = single;
  hyst.rule = ThresholdRule::hysteresis;
  hyst.lower = 1.0 + 0.4 * 3.0;
  hyst.upper = 1.0 + 0.6 * 3.0;
  awcc::Binariser a(single, 1.0), b(hyst, 1.0);
  a.feed(v, 0, 1);
  b.feed(v, 0, 1);
  EXPECT_GT(a.finish().intervals.size(), 1u);
  EXPECT_EQ(b.finish().intervals.size(), 1u);
}

TEST(Threshold, BinaryInputIsNotThresholdedAgain) {
  VoltageHistogram h(1.0);
  std::vector<float> v{0, 1, 1, 0, 0, 1};
  h.add(v, 0, 1);
  BinarisationOptions o;
  o.probe = awcc::ProbeType::conductivity;  // would call the low level air for a voltage
  const auto t = awcc::choose_threshold(h, o);
  EXPECT_TRUE(t.binary_input);
  awcc::Binariser b(t, 1.0);
  b.feed(v, 0, 1);
  const auto s = b.finish();
  EXPECT_EQ(awcc::to_dense(s), (std::vector<std::uint8_t>{0, 1, 1, 0, 0, 1}));
}

TEST(Threshold, ConstantChannelIsWaterWithANote) {
  VoltageHistogram h(5.0 / 32768.0);
  std::vector<float> v(100, 4.1f);
  h.add(v, 0, 1);
  const auto t = awcc::choose_threshold(h, {});
  EXPECT_TRUE(t.constant);
  awcc::Binariser b(t, 1.0);
  b.feed(v, 0, 1);
  EXPECT_EQ(b.finish().air_samples(), 0);
  EXPECT_FALSE(t.note.empty());
}

TEST(BinarisationOptions, Validation) {
  BinarisationOptions o;
  EXPECT_TRUE(o.validate().ok());
  o.theta = 1.2;
  EXPECT_FALSE(o.validate().ok());
  o = {};
  o.hysteresis_low = 0.7;
  EXPECT_FALSE(o.validate().ok());
}

}  // namespace

namespace {

// Samples of given values (V) and counts, histogrammed at 0.01 V.
VoltageHistogram histogram_of(const std::vector<std::pair<float, int>>& values) {
  VoltageHistogram h(0.01);
  std::vector<float> v;
  for (const auto& [value, n] : values) v.insert(v.end(), static_cast<std::size_t>(n), value);
  h.add(v, 0, 1);
  return h;
}

// thres.m on a hand-made record from 0 V to 10 V: 100 bins of 0.1 V, centres
// 0.05 .. 9.95, first split at 9.95 / 2 = 4.975. Air side: 50 samples at
// 0.55 V (bin centre 0.55); water side: 80 at 9.05 V, and 50 at 6.05 V,
// which ties with the air side's largest count: thres.m averages that bin
// into the air mode, (0.55 + 6.05) / 2 = 3.3 V; threshold (3.3 + 9.05) / 2.
TEST(Threshold, KramerRuleAveragesATieAcrossTheSplitAsThresMDoes) {
  BinarisationOptions o;
  o.rule = ThresholdRule::kramer;
  const auto t = awcc::choose_threshold(histogram_of({{0.0f, 1}, {0.55f, 50}, {6.05f, 50}, {9.05f, 80}, {10.0f, 1}}), o);
  EXPECT_NEAR(t.air_level, 3.3, 1e-9);
  EXPECT_NEAR(t.water_level, 9.05, 1e-9);
  EXPECT_NEAR(t.threshold, (3.3 + 9.05) / 2, 1e-9);
  EXPECT_NE(t.note.find("quirk"), std::string::npos);
  // Without the tie: no quirk, the air mode is its own bin.
  const auto plain = awcc::choose_threshold(histogram_of({{0.0f, 1}, {0.55f, 50}, {6.05f, 40}, {9.05f, 80}, {10.0f, 1}}), o);
  EXPECT_NEAR(plain.air_level, 0.55, 1e-9);
  EXPECT_TRUE(plain.note.empty());
}

TEST(Threshold, KramerRulePutsAValueOnABinEdgeInTheBinBelow) {
  // MATLAB's hist shifts each edge up by eps: 60 samples at exactly 2.0 V
  // (the edge between the bins centred on 1.95 and 2.05) count in the bin
  // centred on 1.95, which becomes the air mode.
  BinarisationOptions o;
  o.rule = ThresholdRule::kramer;
  const auto t = awcc::choose_threshold(histogram_of({{0.0f, 1}, {2.0f, 60}, {0.55f, 50}, {9.05f, 80}, {10.0f, 1}}), o);
  EXPECT_NEAR(t.air_level, 1.95, 1e-9);
  EXPECT_NEAR(t.threshold, (1.95 + 9.05) / 2, 1e-9);
}

TEST(BinarisationOptions, TheTrailingTipsOwnThresholdIsAFixedRuleVoltage) {
  BinarisationOptions o;
  o.rule = ThresholdRule::fixed;
  o.fixed_threshold = 2.7;
  o.fixed_threshold_trailing = 2.6;
  EXPECT_TRUE(o.validate().ok());
  EXPECT_DOUBLE_EQ(*o.for_trailing_tip().fixed_threshold, 2.6);
  o.fixed_threshold_trailing.reset();
  EXPECT_DOUBLE_EQ(*o.for_trailing_tip().fixed_threshold, 2.7);
  o.rule = ThresholdRule::histogram;
  o.fixed_threshold_trailing = 2.6;
  EXPECT_NE(o.validate().message.find("fixed rule"), std::string::npos);
  EXPECT_EQ(o.validate().quantity, "threshold-rule");
}

}  // namespace
