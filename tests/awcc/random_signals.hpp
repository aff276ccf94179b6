#pragma once
// Random binary test signals for the correlation tests.

#include <cstdint>
#include <random>
#include <vector>

#include "awcc/air_intervals.hpp"

namespace pdp_test {

/// A random telegraph signal of n samples starting in water: air chords of
/// min_length .. min_length + max_air - 1 samples, water chords of
/// min_length .. min_length + max_water - 1.
inline awcc::AirIntervals telegraph(std::int64_t n, unsigned seed, double fs = 1000.0, int max_air = 10,
                                    int max_water = 40, int min_length = 1) {
  std::mt19937 rng(seed);
  std::vector<std::uint8_t> dense(static_cast<std::size_t>(n));
  std::uint8_t state = 0;
  std::int64_t next = 0;
  for (std::int64_t i = 0; i < n; ++i) {
    if (i == next) {
      state ^= 1;
      next = i + min_length + static_cast<std::int64_t>(rng() % static_cast<unsigned>(state ? max_air : max_water));
    }
    dense[static_cast<std::size_t>(i)] = state;
  }
  return awcc::from_dense(dense, fs);
}

}  // namespace pdp_test
