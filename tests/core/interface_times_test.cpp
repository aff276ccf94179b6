#include "awcc/interface_times.hpp"

#include <gtest/gtest.h>

namespace {

// A bubble of 3 air samples [4, 7) at 1 kHz: the rising edge lies between
// samples 3 and 4 (3.5 ms), the falling edge between samples 6 and 7 (6.5 ms).
TEST(InterfaceTimes, EdgesLieHalfWayBetweenTheStraddlingSamples) {
  awcc::AirIntervals tip;
  tip.fs = 1000.0;
  tip.sample_count = 20;
  tip.intervals = {{4, 7}, {10, 11}};
  const auto c = awcc::crossings(tip);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_DOUBLE_EQ(c[0].front, 3.5e-3);
  EXPECT_DOUBLE_EQ(c[0].rear, 6.5e-3);
  EXPECT_DOUBLE_EQ(c[0].chord_time(), 3e-3);  // exactly the air samples' duration
  EXPECT_DOUBLE_EQ(c[0].centre(), 5e-3);
  EXPECT_DOUBLE_EQ(c[1].chord_time(), 1e-3);
  EXPECT_FALSE(c[0].censored);
  EXPECT_FALSE(c[1].censored);
}

TEST(InterfaceTimes, BubblesCutByTheRecordEndsAreCensored) {
  awcc::AirIntervals tip;
  tip.fs = 100.0;
  tip.sample_count = 10;
  tip.intervals = {{0, 2}, {4, 5}, {8, 10}};
  const auto c = awcc::crossings(tip);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_TRUE(c[0].censored);
  EXPECT_FALSE(c[1].censored);
  EXPECT_TRUE(c[2].censored);
  // One sample short of each end is not cut.
  tip.intervals = {{1, 2}, {8, 9}};
  for (const auto& crossing : awcc::crossings(tip)) EXPECT_FALSE(crossing.censored);
}

TEST(InterfaceTimes, AnEmptyRecordHasNoCrossings) {
  awcc::AirIntervals tip;
  EXPECT_TRUE(awcc::crossings(tip).empty());
}

}  // namespace
