#pragma once
// Binary test signals built from others: a delayed copy, the complement, a
// square wave. For the decision-rule and result-status tests.

#include <cstdint>
#include <vector>

#include "awcc/air_intervals.hpp"

namespace pdp_test {

/// The signal delayed by `delay` samples (negative: advanced); samples
/// shifted in from outside the record are water.
inline awcc::AirIntervals shifted(const awcc::AirIntervals& s, std::int64_t delay) {
  const auto dense = awcc::to_dense(s);
  std::vector<std::uint8_t> out(dense.size(), 0);
  const auto n = static_cast<std::int64_t>(dense.size());
  for (std::int64_t i = 0; i < n; ++i) {
    const std::int64_t j = i + delay;
    if (j >= 0 && j < n) out[static_cast<std::size_t>(j)] = dense[static_cast<std::size_t>(i)];
  }
  return awcc::from_dense(out, s.fs);
}

/// Air where the signal is water and water where it is air.
inline awcc::AirIntervals complement(const awcc::AirIntervals& s) {
  auto dense = awcc::to_dense(s);
  for (auto& v : dense) v = static_cast<std::uint8_t>(1 - v);
  return awcc::from_dense(dense, s.fs);
}

/// n samples of a square wave: `water` samples of water, then `air` of air,
/// repeated; sample i takes the value of position (i + phase) of the pattern.
inline awcc::AirIntervals square_wave(std::int64_t n, std::int64_t water, std::int64_t air, double fs,
                                      std::int64_t phase = 0) {
  std::vector<std::uint8_t> dense(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) dense[static_cast<std::size_t>(i)] = ((i + phase) % (water + air)) >= water ? 1 : 0;
  return awcc::from_dense(dense, fs);
}

/// An empty (all-water) record of the same length and rate as s.
inline awcc::AirIntervals all_water_like(const awcc::AirIntervals& s) {
  awcc::AirIntervals w;
  w.fs = s.fs;
  w.sample_count = s.sample_count;
  return w;
}

}  // namespace pdp_test
