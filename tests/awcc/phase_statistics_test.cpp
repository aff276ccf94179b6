#include "awcc/phase_statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

TEST(PhaseStatistics, HandComputedValues) {
  // 100 samples at 10 Hz (10 s). Air: [0, 5) cut by the start, [20, 30),
  // [50, 54), [80, 100) cut by the end. Complete chords: 10 and 4 samples.
  awcc::AirIntervals s;
  s.fs = 10.0;
  s.sample_count = 100;
  s.intervals = {{0, 5}, {20, 30}, {50, 54}, {80, 100}};
  const auto p = awcc::phase_statistics(s);
  EXPECT_DOUBLE_EQ(p.duration, 10.0);
  EXPECT_DOUBLE_EQ(p.void_fraction, 39.0 / 100.0);
  EXPECT_DOUBLE_EQ(p.bubble_count_rate, 2.0 / 10.0);  // two complete chords
  EXPECT_EQ(p.air_chord_time.count, 2);
  EXPECT_DOUBLE_EQ(p.air_chord_time.mean, 0.7);       // (1.0 + 0.4) / 2
  EXPECT_DOUBLE_EQ(p.air_chord_time.median, 0.7);
  EXPECT_NEAR(p.air_chord_time.std, std::sqrt(0.18), 1e-12);  // ((0.3)^2 + (0.3)^2) / 1
  // Water chords between air chords: 15, 20, 26 samples.
  EXPECT_EQ(p.water_chord_time.count, 3);
  EXPECT_NEAR(p.water_chord_time.mean, 61.0 / 30.0, 1e-12);
  EXPECT_DOUBLE_EQ(p.water_chord_time.median, 2.0);
  // Arrivals between chord starts, except from the chord cut by the start:
  // 50 - 20 = 30, 80 - 50 = 30 samples.
  EXPECT_EQ(p.interarrival_time.count, 2);
  EXPECT_DOUBLE_EQ(p.interarrival_time.mean, 3.0);
  EXPECT_FALSE(p.sauter_diameter.has_value());

  awcc::PhaseStatisticsOptions o;
  o.velocity = 2.0;
  const auto q = awcc::phase_statistics(s, o);
  ASSERT_TRUE(q.sauter_diameter.has_value());
  EXPECT_DOUBLE_EQ(*q.sauter_diameter, 1.5 * 2.0 * 0.39 / 0.2);
  EXPECT_DOUBLE_EQ(q.air_chord_length->mean, 1.4);
}

TEST(Summary, PercentilesAndIntervals) {
  std::vector<double> v;
  for (int i = 1; i <= 101; ++i) v.push_back(i);
  const auto s = awcc::summarise(v);
  EXPECT_DOUBLE_EQ(s.median, 51.0);
  EXPECT_DOUBLE_EQ(s.percentiles[0], 6.0);   // 5th: position 0.05 * 100 = 5 -> value 6
  EXPECT_DOUBLE_EQ(s.percentiles[6], 96.0);
  const double sd = std::sqrt(101.0 * 102.0 / 12.0);  // sample sd of 1..101 = sqrt(n(n+1)/12)
  EXPECT_NEAR(s.std, sd, 1e-9);
  EXPECT_NEAR(s.mean_ci95.upper - s.mean, 1.96 * sd / std::sqrt(101.0), 1e-9);
  // Median CI: ranks 50.5 -/+ 1.96 * sqrt(101) / 2 = 9.85 -> values 41 and 61.
  EXPECT_DOUBLE_EQ(s.median_ci95.lower, 41.0);
  EXPECT_DOUBLE_EQ(s.median_ci95.upper, 61.0);
}

TEST(PhaseStatistics, ConstantChannelHasNoChords) {
  awcc::AirIntervals s;
  s.fs = 100;
  s.sample_count = 1000;
  const auto p = awcc::phase_statistics(s);
  EXPECT_EQ(p.void_fraction, 0.0);
  EXPECT_EQ(p.bubble_count_rate, 0.0);
  s.intervals = {{0, 1000}};
  const auto q = awcc::phase_statistics(s);
  EXPECT_EQ(q.void_fraction, 1.0);
  EXPECT_EQ(q.bubble_count_rate, 0.0);
  for (double x : {q.void_fraction_ci95.lower, q.void_fraction_ci95.upper, q.air_chord_time.mean}) {
    EXPECT_TRUE(std::isfinite(x));
  }
}

}  // namespace

namespace {

awcc::AirIntervals record(std::vector<awcc::AirInterval> iv, std::int64_t n) {
  awcc::AirIntervals s;
  s.intervals = std::move(iv);
  s.sample_count = n;
  s.fs = 1000.0;
  return s;
}

}  // namespace

// Each status at its limit: the intervals need 2 complete air and 2 water
// chords; with fewer, the status says so (the interval is the point).
TEST(PhaseStatus, EachStatusAtItsLimit) {
  EXPECT_EQ(awcc::phase_statistics(record({}, 100)).status, awcc::PhaseStatus::no_air);
  EXPECT_EQ(awcc::phase_statistics(record({{0, 100}}, 100)).status, awcc::PhaseStatus::all_air);
  // Two complete air chords but one water chord between them: too few.
  const auto one_water = awcc::phase_statistics(record({{10, 20}, {30, 40}}, 100));
  EXPECT_EQ(one_water.status, awcc::PhaseStatus::too_few_chords);
  EXPECT_EQ(one_water.void_fraction_ci95.lower, one_water.void_fraction);
  EXPECT_NE(one_water.message.find("2 complete air and 1 water"), std::string::npos) << one_water.message;
  // Three air chords, two water chords between them: intervals exist.
  const auto enough = awcc::phase_statistics(record({{10, 20}, {30, 45}, {60, 62}}, 100));
  EXPECT_EQ(enough.status, awcc::PhaseStatus::ok);
  EXPECT_LT(enough.void_fraction_ci95.lower, enough.void_fraction);
  EXPECT_GT(enough.void_fraction_ci95.upper, enough.void_fraction);
}

// The dispersed phase's fraction at and around its rule's limit: bubbles'
// c up to 0.5, droplets' 1 - c above, continuous at 0.5 (d32 and the sizes
// read it).
TEST(DispersedFraction, BubblesUpToOneHalfDropletsAbove) {
  EXPECT_EQ(awcc::dispersed_fraction(0.2), 0.2);
  EXPECT_EQ(awcc::dispersed_fraction(0.5), 0.5);
  EXPECT_EQ(awcc::dispersed_particle(0.5), "bubble");
  EXPECT_NEAR(awcc::dispersed_fraction(std::nextafter(0.5, 1.0)), 0.5, 1e-15);
  EXPECT_EQ(awcc::dispersed_particle(std::nextafter(0.5, 1.0)), "droplet");
  EXPECT_DOUBLE_EQ(awcc::dispersed_fraction(0.9), 0.1);
}
