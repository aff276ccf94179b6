// Cluster analysis (awcc/clusters.hpp) on hand-made chord sequences whose
// clusters are known, for the default analysis and Felder's, at the edge
// cases of felder-program.md 7.
#include <gtest/gtest.h>

#include "awcc/clusters.hpp"

namespace {

// Bubbles of the given air chords, each followed by the given water chord
// (samples), from sample `first`, in a record of n samples at fs.
awcc::AirIntervals bubbles(const std::vector<std::pair<int, int>>& air_then_water, std::int64_t first, std::int64_t n,
                           double fs) {
  awcc::AirIntervals s;
  s.sample_count = n;
  s.fs = fs;
  std::int64_t t = first;
  for (const auto& [air, water] : air_then_water) {
    s.intervals.push_back({t, t + air});
    t += air + water;
  }
  return s;
}

const awcc::ClusterStatistics& by(const awcc::ClusterAnalysis& a, awcc::ClusterCriterion c) {
  for (const auto& s : a.criteria)
    if (s.criterion == c) return s;
  throw std::logic_error("criterion missing");
}

// fs 10 kHz, record 1 s (10 000 samples): the constant criterion of 1 ms is
// 10 samples. Air chords (samples) and the water chord after each:
//   b1 5|8  b2 5|8  b3 5|100  b4 20|15  b5 20|100  b6 5|5  b7 5|5  b8 5
// constant (water <= 10): pairs 1-2, 2-3, 6-7, 7-8 -> {b1 b2 b3}, {b6 b7 b8};
// near-wake (water <= the leader's air chord): 4-5, 6-7, 7-8 -> {b4 b5}, {b6 b7 b8};
// median: 0.1 x median water (8) = 0.8 samples: no pair, no cluster.
const std::vector<std::pair<int, int>> kBubbly{{5, 8}, {5, 8}, {5, 100}, {20, 15}, {20, 100}, {5, 5}, {5, 5}, {5, 0}};

TEST(Clusters, DefaultFindsTheKnownClustersIncludingARunToTheLastSeparation) {
  const auto c = awcc::complete_chords(bubbles(kBubbly, 100, 10'000, 10e3));
  const auto a = awcc::cluster_analysis(c, 0.01, awcc::ChordBasis::time, {});
  ASSERT_EQ(a.status, awcc::ClusterStatus::ok) << a.message;
  EXPECT_EQ(a.regime, awcc::FlowRegime::bubbly);
  const auto& k = by(a, awcc::ClusterCriterion::constant);
  EXPECT_EQ(k.particles, 8);
  EXPECT_EQ(k.in_clusters, 6);
  EXPECT_EQ(k.clusters, 2);
  EXPECT_DOUBLE_EQ(k.percent_in_clusters, 75.0);
  EXPECT_DOUBLE_EQ(k.clusters_per_second, 2.0);
  EXPECT_DOUBLE_EQ(*k.mean_particles_per_cluster, 3.0);
  EXPECT_NEAR(*k.mean_chord_in_cluster, 0.5e-3, 1e-15);
  EXPECT_NEAR(*k.ratio_cluster_chord_to_mean_chord, 5.0 / 8.75, 1e-12);  // mean of all: 70 / 8 samples
  EXPECT_NEAR(*k.ratio_lead_to_cluster_mean_chord, 1.0, 1e-12);
  EXPECT_EQ(k.size_counts[1], 2);  // two clusters of 3
  EXPECT_DOUBLE_EQ((*k.size_pdf)[1], 1.0);
  const auto& w = by(a, awcc::ClusterCriterion::near_wake);
  EXPECT_EQ(w.in_clusters, 5);
  EXPECT_EQ(w.clusters, 2);
  EXPECT_NEAR(*w.mean_chord_in_cluster, 1.1e-3, 1e-15);  // (20 + 20 + 5 + 5 + 5) / 5 samples
  const auto& m = by(a, awcc::ClusterCriterion::median);
  EXPECT_NEAR(*m.criterion_value, 0.08e-3, 1e-15);
  EXPECT_EQ(m.clusters, 0);
  EXPECT_FALSE(m.mean_particles_per_cluster);  // no cluster: no mean, not 0/0
  EXPECT_FALSE(m.size_pdf);
}

TEST(Clusters, FeldersDropsTheRunThatReachesTheLastSeparation) {
  // Same bubbles; his last bubble is stretched to the record's end and his
  // loop stops before the last separation: only {b1 b2 b3}.
  const auto f = awcc::felder_chords(bubbles(kBubbly, 100, 10'000, 10e3));
  ASSERT_EQ(f.n_cluster, 8);
  const auto a = awcc::felder_cluster_analysis(f, 0.01, awcc::ChordBasis::time, {});
  ASSERT_EQ(a.status, awcc::ClusterStatus::ok) << a.message;
  const auto& k = by(a, awcc::ClusterCriterion::constant);
  EXPECT_EQ(k.in_clusters, 3);
  EXPECT_EQ(k.clusters, 1);
  EXPECT_DOUBLE_EQ(k.percent_in_clusters, 37.5);
  EXPECT_NEAR(*k.mean_chord_in_cluster, 0.5e-3, 1e-12);
  // Near-wake: {b4 b5} and {b6 b7} (the pair 7-8 is past his loop).
  const auto& w = by(a, awcc::ClusterCriterion::near_wake);
  EXPECT_EQ(w.clusters, 2);
  EXPECT_EQ(w.in_clusters, 4);
}

TEST(Clusters, EqualChordsInTheWakeTestCountABubbleOnceByDefaultAndTwiceInFelders) {
  // b2 20|15  b3 20|20  b4 5|100: b3 follows b2 (15 <= 20) and b4 follows b3
  // (20 <= 20: equal). Default: one cluster {b2 b3 b4}. Felder's: b3's equal
  // water chord closes {b2 b3} and opens {b3 b4}: two clusters, b3 in both.
  const std::vector<std::pair<int, int>> b{{5, 100}, {20, 15}, {20, 20}, {5, 100}, {5, 100}, {5, 0}};
  const auto s = bubbles(b, 100, 10'000, 10e3);
  const auto d = awcc::cluster_analysis(awcc::complete_chords(s), 0.01, awcc::ChordBasis::time, {});
  EXPECT_EQ(by(d, awcc::ClusterCriterion::near_wake).clusters, 1);
  EXPECT_EQ(by(d, awcc::ClusterCriterion::near_wake).in_clusters, 3);
  const auto f = awcc::felder_cluster_analysis(awcc::felder_chords(s), 0.01, awcc::ChordBasis::time, {});
  EXPECT_EQ(by(f, awcc::ClusterCriterion::near_wake).clusters, 2);
  EXPECT_EQ(by(f, awcc::ClusterCriterion::near_wake).in_clusters, 4);
}

TEST(Clusters, DropletsUseTheAirChordBetweenThemAndFeldersTheOneBefore) {
  // Mostly air (c = 0.81): 1 sample of water, then air chords 200 5 5 200 200
  // 200 with droplets of 10 20 30 40 50 samples between them, then water to
  // 1000 samples at 10 kHz. The air chord between droplets i and i+1 is
  // a_{i+1}: 5, 5, 200, 200 -> constant criterion: droplets {10 20 30}, mean
  // 20 samples = 2 ms, lead 10 / 20. Felder's tests a_i (one before):
  // droplets {20 30 40}, mean 3 ms, lead 20 / 30.
  const std::vector<std::pair<int, int>> b{{200, 10}, {5, 20}, {5, 30}, {200, 40}, {200, 50}, {200, 0}};
  const auto s = bubbles(b, 1, 1000, 10e3);
  EXPECT_NEAR(s.void_fraction(), 0.81, 1e-12);
  const auto d = awcc::cluster_analysis(awcc::complete_chords(s), s.void_fraction(), awcc::ChordBasis::time, {});
  ASSERT_EQ(d.status, awcc::ClusterStatus::ok) << d.message;
  EXPECT_EQ(d.regime, awcc::FlowRegime::droplet);
  const auto& k = by(d, awcc::ClusterCriterion::constant);
  EXPECT_EQ(k.particles, 5);
  EXPECT_EQ(k.clusters, 1);
  EXPECT_NEAR(*k.mean_chord_in_cluster, 2e-3, 1e-15);
  EXPECT_NEAR(*k.ratio_lead_to_cluster_mean_chord, 0.5, 1e-12);
  const auto f = awcc::felder_cluster_analysis(awcc::felder_chords(s), s.void_fraction(), awcc::ChordBasis::time, {});
  ASSERT_EQ(f.status, awcc::ClusterStatus::ok) << f.message;
  const auto& fk = by(f, awcc::ClusterCriterion::constant);
  EXPECT_EQ(fk.clusters, 1);
  EXPECT_NEAR(*fk.mean_chord_in_cluster, 3e-3, 1e-9);
  EXPECT_NEAR(*fk.ratio_lead_to_cluster_mean_chord, 2.0 / 3.0, 1e-7);
  EXPECT_DOUBLE_EQ(fk.percent_in_clusters, static_cast<double>(3.0f / 5.0f * 100.0f));  // of n - 1 droplets
}

TEST(Clusters, ASprayRecordThatStartsAndEndsInAirKeepsItsEndDroplets) {
  // A spray record (issue 31): air cut by the start (100 samples), droplets
  // of 10, 20 and 30 samples with air chords of 5 and 200 between them, air
  // to the record's end at 10 kHz, c = 0.994. The droplets next to the cut
  // air are complete: three particles, where the water chords between
  // complete bubbles alone are one (the defect issue 31 found: two complete
  // droplets of every spray record dropped). Constant criterion (1 ms = 10
  // samples): the first two cluster, mean chord 1.5 ms, lead 10 / 15.
  const auto s = bubbles({{100, 10}, {5, 20}, {200, 30}, {9635, 0}}, 0, 10'000, 10e3);
  ASSERT_EQ(s.intervals.back().stop, 10'000);
  const auto chords = awcc::complete_chords(s);
  EXPECT_EQ(chords.bubbles(), 2u);
  const auto droplets = awcc::complete_droplets(chords);
  ASSERT_EQ(droplets.droplets(), 3u);
  EXPECT_EQ(droplets.water(0), 10);
  EXPECT_EQ(droplets.water(2), 30);
  EXPECT_EQ(droplets.air(0), 5);
  EXPECT_EQ(droplets.air(1), 200);
  const auto d = awcc::cluster_analysis(chords, s.void_fraction(), awcc::ChordBasis::time, {});
  ASSERT_EQ(d.status, awcc::ClusterStatus::ok) << d.message;
  EXPECT_EQ(d.regime, awcc::FlowRegime::droplet);
  const auto& k = by(d, awcc::ClusterCriterion::constant);
  EXPECT_EQ(k.particles, 3);
  EXPECT_EQ(k.clusters, 1);
  EXPECT_EQ(k.in_clusters, 2);
  EXPECT_NEAR(*k.mean_chord_in_cluster, 1.5e-3, 1e-15);
  EXPECT_NEAR(*k.ratio_lead_to_cluster_mean_chord, 10.0 / 15.0, 1e-12);
  // One air interval filling the record: no droplet at all; one cut at each
  // end and nothing between: the one droplet between them.
  const auto all_air = bubbles({{10'000, 0}}, 0, 10'000, 10e3);
  EXPECT_EQ(awcc::complete_droplets(awcc::complete_chords(all_air)).droplets(), 0u);
  const auto one = bubbles({{100, 50}, {9850, 0}}, 0, 10'000, 10e3);
  const auto single = awcc::complete_droplets(awcc::complete_chords(one));
  ASSERT_EQ(single.droplets(), 1u);
  EXPECT_EQ(single.start[0], 100);
  EXPECT_EQ(single.end[0], 150);
}

TEST(Clusters, NothingBetweenTheRegimesAndTooFewParticlesAreSaid) {
  EXPECT_EQ(awcc::flow_regime(0.2999), awcc::FlowRegime::bubbly);
  EXPECT_EQ(awcc::flow_regime(0.3), awcc::FlowRegime::intermediate);
  EXPECT_EQ(awcc::flow_regime(0.7), awcc::FlowRegime::intermediate);
  EXPECT_EQ(awcc::flow_regime(0.7001), awcc::FlowRegime::droplet);
  const auto s = bubbles(kBubbly, 100, 10'000, 10e3);
  const auto mid = awcc::cluster_analysis(awcc::complete_chords(s), 0.5, awcc::ChordBasis::time, {});
  EXPECT_EQ(mid.status, awcc::ClusterStatus::intermediate_void_fraction);
  EXPECT_TRUE(mid.criteria.empty());
  EXPECT_NE(mid.message.find("0.3 to 0.7"), std::string::npos);
  // Zero and one bubble; a record that starts and ends in air (its two cut
  // bubbles are not chords by default).
  for (const auto& few : {bubbles({}, 0, 1000, 10e3), bubbles({{5, 0}}, 100, 1000, 10e3),
                          bubbles({{50, 100}, {5, 100}, {5, 100}, {640, 0}}, 0, 1000, 10e3)}) {
    const auto a = awcc::cluster_analysis(awcc::complete_chords(few), 0.01, awcc::ChordBasis::time, {});
    EXPECT_EQ(a.status, awcc::ClusterStatus::too_few_particles);
    const auto f = awcc::felder_cluster_analysis(awcc::felder_chords(few), 0.01, awcc::ChordBasis::time, {});
    if (few.intervals.size() < 3) {
      EXPECT_EQ(f.status, awcc::ClusterStatus::too_few_particles);
    }
  }
  // By length without a velocity: said, not computed.
  const auto nolength = awcc::cluster_analysis(awcc::complete_chords(s), 0.01, awcc::ChordBasis::length, {});
  EXPECT_EQ(nolength.status, awcc::ClusterStatus::no_velocity);
}

TEST(Clusters, LengthBasisScalesChordsByTheVelocity) {
  // At 2 m/s a 5-sample chord (0.5 ms) is 1 mm; the constant criterion of
  // 1 mm is 5 samples of water: only the pairs 6-7, 7-8 (water 5).
  const auto c = awcc::complete_chords(bubbles(kBubbly, 100, 10'000, 10e3));
  const auto a = awcc::cluster_analysis(c, 0.01, awcc::ChordBasis::length, {}, 2.0);
  const auto& k = by(a, awcc::ClusterCriterion::constant);
  EXPECT_EQ(k.clusters, 1);
  EXPECT_EQ(k.in_clusters, 3);
  EXPECT_NEAR(*k.mean_chord_in_cluster, 1e-3, 1e-15);
}

}  // namespace
