#include "awcc/air_intervals.hpp"

#include <gtest/gtest.h>

#include <random>

namespace {

using awcc::AirInterval;
using awcc::AirIntervals;

TEST(AirIntervals, NormaliseMergesOverlappingAndTouchingIntervals) {
  std::vector<AirInterval> v{{10, 20}, {0, 5}, {18, 25}, {25, 30}, {40, 41}, {7, 7}};
  awcc::normalise(v);
  const std::vector<AirInterval> expected{{0, 5}, {10, 30}, {40, 41}};
  EXPECT_EQ(v, expected);
}

TEST(AirIntervals, DenseRoundTripAndBlockRendering) {
  // A random 0/1 signal: from_dense then to_dense must give it back, and any
  // block of render() must equal the same slice of the dense vector.
  std::mt19937 rng(7);
  std::vector<std::uint8_t> dense(5000);
  std::uint8_t state = 0;
  for (auto& s : dense) {
    if (rng() % 13 == 0) state ^= 1;
    s = state;
  }
  const AirIntervals signal = awcc::from_dense(dense, 1000.0);
  EXPECT_TRUE(signal.check().empty());
  EXPECT_EQ(awcc::to_dense(signal), dense);
  std::int64_t air = 0;
  for (auto s : dense) air += s;
  EXPECT_EQ(signal.air_samples(), air);
  EXPECT_DOUBLE_EQ(signal.void_fraction(), static_cast<double>(air) / 5000.0);
  for (std::int64_t first : {0, 1, 999, 4000}) {
    for (std::size_t n : {1u, 17u, 1000u}) {
      if (first + static_cast<std::int64_t>(n) > 5000) continue;
      std::vector<std::uint8_t> block(n);
      signal.render(first, block);
      EXPECT_TRUE(std::equal(block.begin(), block.end(), dense.begin() + first)) << first << " " << n;
    }
  }
}

TEST(AirIntervals, CheckFindsBrokenLists) {
  AirIntervals s;
  s.sample_count = 100;
  s.intervals = {{10, 20}, {20, 30}};
  EXPECT_FALSE(s.check().empty());  // touching
  s.intervals = {{10, 20}, {5, 8}};
  EXPECT_FALSE(s.check().empty());  // out of order
  s.intervals = {{90, 101}};
  EXPECT_FALSE(s.check().empty());  // outside
  s.intervals = {{0, 1}, {99, 100}};
  EXPECT_TRUE(s.check().empty());
}

}  // namespace

// The shared air samples against a brute-force count over the dense
// signals, on random telegraph-like lists of every overlap pattern.
TEST(AirIntervals, SharedAirSamplesEqualABruteForceCount) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 200; ++trial) {
    const std::int64_t n = 50 + static_cast<std::int64_t>(rng() % 400);
    std::vector<std::uint8_t> x(static_cast<std::size_t>(n)), y(static_cast<std::size_t>(n));
    for (auto* v : {&x, &y}) {
      std::uint8_t state = 0;
      for (auto& s : *v) {
        if (rng() % 7 == 0) state ^= 1;
        s = state;
      }
    }
    std::int64_t both = 0;
    for (std::size_t i = 0; i < x.size(); ++i) both += x[i] && y[i];
    const auto a = awcc::from_dense(x, 1.0), b = awcc::from_dense(y, 1.0);
    EXPECT_EQ(awcc::shared_air_samples(a, b), both) << trial;
    EXPECT_EQ(awcc::shared_air_samples(b, a), both) << trial;
    EXPECT_EQ(awcc::shared_air_samples(a, a), a.air_samples()) << trial;
  }
}
