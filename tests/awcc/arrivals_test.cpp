// Inter-particle arrival times (awcc/arrivals.hpp): hand-made arrivals, the
// reference density's integral, and Felder's conventions.
#include <gtest/gtest.h>

#include <cmath>

#include "awcc/arrivals.hpp"

namespace {

awcc::AirIntervals at(const std::vector<std::int64_t>& starts, std::int64_t chord, std::int64_t n, double fs) {
  awcc::AirIntervals s;
  s.sample_count = n;
  s.fs = fs;
  for (auto t : starts) s.intervals.push_back({t, t + chord});
  return s;
}

TEST(RandomArrivals, TheReferenceIntegratesToOneAndIsNearlyExponential) {
  // Over [0, T] the bins sum to 1 (the density is normalised); for t << T it
  // is lambda exp(-lambda t) to O(t / T + 1 / N).
  const std::int64_t n = 500;
  const double t = 100.0;
  double total = 0.0;
  for (int m = 0; m < 1000; ++m) total += awcc::random_arrival_probability(m * 0.1, (m + 1) * 0.1, n, t);
  EXPECT_NEAR(total, 1.0, 1e-12);
  const double lambda = n / t;
  const double exponential = std::exp(-lambda * 0.01) - std::exp(-lambda * 0.02);
  EXPECT_NEAR(awcc::random_arrival_probability(0.01, 0.02, n, t), exponential, exponential * 3e-3);
}

TEST(Arrivals, DefaultMeasuresStartToStartAndNormalisesByIntervals) {
  // fs 10 kHz, 10 s. Bubbles of 3 samples (0.3 ms: the smallest time class)
  // starting at samples 1000, 1021, 1100, 2000 and 3600: start-to-start 2.1,
  // 7.9, 90 and 160 ms -> bins 3, 8, 90 and the overflow; four intervals.
  const auto s = at({1000, 1021, 1100, 2000, 3600}, 3, 100'000, 10e3);
  const auto a = awcc::arrival_analysis(awcc::complete_chords(s), 0.01, awcc::ChordBasis::time, {});
  ASSERT_EQ(a.status, awcc::ClusterStatus::ok) << a.message;
  const auto& c = a.classes[0];
  EXPECT_EQ(c.particles, 5);
  EXPECT_EQ(c.intervals, 4);
  ASSERT_EQ(c.counts.size(), 101u);
  EXPECT_EQ(c.counts[2], 1);
  EXPECT_EQ(c.counts[7], 1);
  EXPECT_EQ(c.counts[89], 1);
  EXPECT_EQ(c.counts[100], 1);
  EXPECT_DOUBLE_EQ(c.pdf[2], 0.25);
  for (std::size_t k = 1; k < a.classes.size(); ++k) EXPECT_EQ(a.classes[k].particles, 0);
  // The reference of N = 5 in 10 s, integrated over the first bin.
  EXPECT_NEAR(c.reference[0], awcc::random_arrival_probability(0.0, 1e-3, 5, 10.0), 1e-15);
  EXPECT_NEAR(*c.excess_first_bin, 0.0, 1e-15);  // nothing in the first bin
}

TEST(Arrivals, FeldersMeasuresEdgeToEdgeAndNormalisesByParticles) {
  // The same bubbles: his intervals run from a bubble's end to the next
  // one's start: 1.8, 7.6, 89.7, 159.7 ms -> bins 2, 8, 90, and 100 for the
  // overflow; PDF = count / N = 1/5. His last bubble is stretched to the
  // record's end (a chord of 9.64 s: the largest class).
  const auto s = at({1000, 1021, 1100, 2000, 3600}, 3, 100'000, 10e3);
  const auto f = awcc::felder_chords(s);
  ASSERT_EQ(f.n_cluster, 5);
  const auto a = awcc::felder_arrival_analysis(f, 0.01, awcc::ChordBasis::time);
  ASSERT_EQ(a.status, awcc::ClusterStatus::ok) << a.message;
  const auto& c = a.classes[0];
  EXPECT_EQ(c.particles, 4);
  EXPECT_EQ(a.classes[4].particles, 1);
  EXPECT_EQ(c.counts[1], 1);
  EXPECT_EQ(c.counts[7], 1);
  EXPECT_EQ(c.counts[89], 1);
  EXPECT_EQ(c.counts[99], 0);   // the stretched bubble is in another class: three intervals
  EXPECT_DOUBLE_EQ(c.pdf[1], 0.25);
  // His reference at the first bin's upper edge (1 ms), T = 10 000 ms, in float32:
  // (4/T)^2 (T - 1) exp(-4/T) / (3 + exp(-4)).
  const double expected = (4.0 / 1e4) * (4.0 / 1e4) * (1e4 - 1) * std::exp(-4.0 / 1e4) / (3.0 + std::exp(-4.0));
  EXPECT_NEAR(c.reference[0], expected, expected * 1e-6);
}

TEST(Arrivals, TimeClassesOfFeldersDropletsEndAt6ms) {
  // Droplets (c > 0.7) of 5.5 ms fall in his fourth time class (<= 6 ms),
  // not the last; by default (<= 5 ms) in the last.
  awcc::AirIntervals s;
  s.fs = 10e3;
  s.sample_count = 20'000;
  std::int64_t t = 1;
  for (int i = 0; i < 6; ++i) {
    s.intervals.push_back({t, t + 3000});
    t += 3000 + 55;
  }
  ASSERT_GT(s.void_fraction(), 0.7);
  const auto d = awcc::arrival_analysis(awcc::complete_chords(s), s.void_fraction(), awcc::ChordBasis::time, {});
  EXPECT_EQ(d.regime, awcc::FlowRegime::droplet);
  EXPECT_EQ(d.classes[4].particles, 5);
  const auto f = awcc::felder_arrival_analysis(awcc::felder_chords(s), s.void_fraction(), awcc::ChordBasis::time);
  EXPECT_GT(f.classes[3].particles, 0);
  EXPECT_NEAR(*f.classes[3].upper, 6e-3, 1e-15);
}

TEST(Arrivals, NothingBetweenTheRegimes) {
  const auto s = at({1000, 2000, 3000}, 3, 100'000, 10e3);
  const auto a = awcc::arrival_analysis(awcc::complete_chords(s), 0.5, awcc::ChordBasis::time, {});
  EXPECT_EQ(a.status, awcc::ClusterStatus::intermediate_void_fraction);
  EXPECT_TRUE(a.classes.empty());
}

}  // namespace
