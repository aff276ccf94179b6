// Chord sequences and chord PDFs (awcc/chords.hpp): the default's complete
// chords, Felder's bubbles with his defects, and the bins at their edges.
#include <gtest/gtest.h>

#include "awcc/chords.hpp"
#include "awcc/probe_correction.hpp"
#include "awcc/structure.hpp"
#include "awcc/velocity_series.hpp"

namespace {

awcc::AirIntervals signal(std::vector<awcc::AirInterval> intervals, std::int64_t n, double fs) {
  awcc::AirIntervals s;
  s.intervals = std::move(intervals);
  s.sample_count = n;
  s.fs = fs;
  return s;
}

TEST(CompleteChords, DropBubblesCutByTheRecordsEnds) {
  const auto s = signal({{0, 4}, {10, 13}, {20, 26}, {95, 100}}, 100, 1000.0);
  const auto c = awcc::complete_chords(s);
  ASSERT_EQ(c.bubbles(), 2u);
  EXPECT_EQ(c.air(0), 3);
  EXPECT_EQ(c.air(1), 6);
  EXPECT_EQ(c.water(0), 7);
}

TEST(FelderChords, KeepHisDefects) {
  // Starts in air: his first start stays 0, so the chord is one sample too
  // long (5 instead of 4); the last bubble's end is forced to N (chord 100 -
  // 31 = 69 instead of 3); every interval is a bubble.
  const auto s = signal({{0, 4}, {10, 13}, {30, 33}}, 100, 1000.0);
  const auto f = awcc::felder_chords(s);
  ASSERT_EQ(f.chords.bubbles(), 3u);
  EXPECT_EQ(f.chords.air(0), 5);
  EXPECT_EQ(f.chords.air(1), 3);
  EXPECT_EQ(f.chords.air(2), 69);
  EXPECT_EQ(f.chords.water(0), 6);   // 11 - 5 (1-based: first air 11, first water 5)
  EXPECT_EQ(f.chords.water(1), 17);
  // F = fl32(fl32(3 * 1000) / 100) = 30 /s exactly; F D = 3: n = 3 both ways.
  EXPECT_EQ(f.n_pdf, 3);
  EXPECT_EQ(f.n_cluster, 3);
}

TEST(FelderChords, TheFloat32BubbleCountDropsABubble) {
  // n = 47 bubbles in 900 000 samples at 20 kHz: F = fl32(fl32(940000) /
  // 900000) = fl32(1.04444...) = 1.04444444179534912 (rounded down), F x 45 =
  // 46.99999988: his clusters use INT(F D) = 46 bubbles, his PDFs
  // INT(fl32(F D)) = INT(47.0f) = 47.
  std::vector<awcc::AirInterval> iv;
  for (int i = 0; i < 47; ++i) iv.push_back({1000 + i * 1000, 1010 + i * 1000});
  const auto f = awcc::felder_chords(signal(iv, 900'000, 20e3));
  EXPECT_EQ(f.n_pdf, 47);
  EXPECT_EQ(f.n_cluster, 46);
  const auto counts = awcc::felder_counts(signal(iv, 900'000, 20e3));
  EXPECT_EQ(counts.bubble_count_rate, 1.04444444179534912);
}

TEST(FelderCounts, TheLastSampleIsNotCounted) {
  const auto c = awcc::felder_counts(signal({{10, 20}, {90, 100}}, 100, 1000.0));
  EXPECT_DOUBLE_EQ(c.void_fraction, static_cast<double>(static_cast<float>(19.0f / 100.0f)));
  EXPECT_EQ(c.bubbles, 2);
}

TEST(ChordPdf, BinsAreClosedAboveWithAnOverflowBin) {
  // fs 10 kHz, bins of 0.2 ms to 1 ms: 5 bins (0, 0.2], ..., (0.8, 1.0] and the overflow.
  // Air chords 2, 3, 4, 10, 11 samples = 0.2, 0.3, 0.4, 1.0, 1.1 ms.
  std::vector<awcc::AirInterval> iv;
  std::int64_t t = 10;
  for (int len : {2, 3, 4, 10, 11}) {
    iv.push_back({t, t + len});
    t += len + 20;
  }
  const auto c = awcc::complete_chords(signal(iv, t + 10, 10e3));
  const auto p = awcc::chord_pdf(c, awcc::ChordBasis::time, {0.2e-3, 1e-3});
  EXPECT_EQ(p.air_counts, (std::vector<std::int64_t>{1, 2, 0, 0, 1, 1}));
  EXPECT_EQ(p.air_chords, 5);
  EXPECT_DOUBLE_EQ(p.air_fraction[1], 0.4);
  EXPECT_EQ(p.water_counts, (std::vector<std::int64_t>{0, 0, 0, 0, 0, 4}));  // 2 ms water chords: overflow
  // By length at 2 m/s: 0.4, 0.6, 0.8, 2.0, 2.2 mm in 0.5 mm bins to 2 mm.
  const auto l = awcc::chord_pdf(c, awcc::ChordBasis::length, {0.5e-3, 2e-3}, 2.0);
  EXPECT_EQ(l.air_counts, (std::vector<std::int64_t>{1, 2, 0, 1, 1}));
}

TEST(ChordPdf, FeldersNormalisesByHisBubbleCount) {
  std::vector<awcc::AirInterval> iv;
  for (int i = 0; i < 4; ++i) iv.push_back({100 + i * 100, 102 + i * 100});
  const auto f = awcc::felder_chords(signal(iv, 1000, 20e3));
  const auto p = awcc::felder_chord_pdf(f, awcc::ChordBasis::time, {1e-4, 10e-3});
  ASSERT_EQ(p.air_counts.size(), 101u);
  // Chords of 2 samples = 0.1 ms go to the first bin (upper edge inclusive);
  // the last, stretched to the record's end (1000 - 401 = 599 samples), to the overflow.
  EXPECT_EQ(p.air_counts[0], 3);
  EXPECT_EQ(p.air_counts[100], 1);
  EXPECT_DOUBLE_EQ(p.air_fraction[0], static_cast<double>(3.0f / 4.0f));
  EXPECT_DOUBLE_EQ(p.water_fraction[48], 1.0);  // 98 samples = 4.9 ms: bin (4.8, 4.9], all 3 of n_pdf - 1
  EXPECT_EQ(p.lower_edge(84), static_cast<double>(84.0f * 0.1f) * 1e-3);  // his float32 label, printed 8.400001
}

// The options added with the structure, the probe correction and the
// spectrum refuse values that cannot be meant, at and around their limits.
TEST(NewOptions, ValidationRefusesWhatCannotBeMeant) {
  awcc::StructureOptions s;
  EXPECT_TRUE(s.validate().ok());
  s.clusters.median_fraction = 0.0;
  EXPECT_FALSE(s.validate().ok());
  s = {};
  s.chord_time.max = 0.5 * s.chord_time.bin_width;  // less than one bin
  EXPECT_FALSE(s.validate().ok());
  s = {};
  s.arrivals.length_classes = {3e-3, 1e-3};  // not increasing
  EXPECT_FALSE(s.validate().ok());
  s.arrivals.length_classes = {};
  EXPECT_TRUE(s.validate().ok());  // one class: every particle
  awcc::ProbeCorrectionOptions p;
  EXPECT_TRUE(p.validate().ok());
  p.needle_diameter = 0.0;
  EXPECT_FALSE(p.validate().ok());
  p = {};
  p.air_density = p.water_density;
  EXPECT_FALSE(p.validate().ok());
  p = {};
  p.contact_factor = -0.1;
  EXPECT_FALSE(p.validate().ok());
  p = {};
  p.max_steps = 99;
  EXPECT_FALSE(p.validate().ok());
  awcc::SpectrumOptions sp;
  sp.segment_length = 7;
  EXPECT_FALSE(sp.validate().ok());
  sp.segment_length = 8;
  EXPECT_TRUE(sp.validate().ok());
}

}  // namespace
