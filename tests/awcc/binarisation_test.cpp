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
  EXPECT_TRUE(o.validate().empty());
  o.theta = 1.2;
  EXPECT_FALSE(o.validate().empty());
  o = {};
  o.hysteresis_low = 0.7;
  EXPECT_FALSE(o.validate().empty());
}

}  // namespace
