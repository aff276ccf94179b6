// FSCC's sampling interval (awcc/fscc.hpp) against the scatter it claims to
// cover: sixteen records of one synthetic flow, differing only in their seed,
// give sixteen FSCC velocities. Their standard deviation sd measures the
// record-to-record scatter the interval's half-width h must describe
// (h ~ 1.96 sigma). With K = 16 records, sd / sigma follows
// sqrt(chi2_15 / 15): between 0.52 and 1.63 with probability 0.999, so an
// exact interval gives h / (1.96 sd) within 0.61-1.93. The derivation is
// conservative by design (its rounding term and segments of few bubbles), so
// the bounds are 0.6 and 2.5: an interval from S instead of sqrt(S)
// (factor 0.32) or without the sqrt(S) (3.2) fails. At 100 kHz the lag is
// ~225 samples, so the segments' scatter, not the rounding, sets h.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "awcc/fscc.hpp"
#include "synth/synthesiser.hpp"

namespace {

TEST(FsccInterval, HalfWidthMatchesTheRecordToRecordScatterOfSixteenRecords) {
  synth::Scene s;
  s.velocity = 3.0;
  s.tu = 0.3;
  s.time_scale = 5e-3;
  s.void_fraction = 0.01;
  s.bubble_diameter = 3e-3;
  s.dx = 7.15e-3;
  s.dy = 0.0;
  s.fs = 100e3;
  s.duration = 20.0;
  std::vector<double> velocities, halves;
  int covering = 0;
  for (std::uint64_t seed = 1; seed <= 16; ++seed) {
    s.seed = seed;
    const auto syn = synth::synthesise(s);
    const auto f = awcc::fscc(syn.signals[0], syn.signals[1], s.dx);
    ASSERT_TRUE(f.ok()) << f.message;
    ASSERT_TRUE(f.velocity_ci95) << "seed " << seed << ": " << f.interval_segments << " segments with a peak";
    velocities.push_back(f.velocity);
    halves.push_back(0.5 * (f.velocity_ci95->upper - f.velocity_ci95->lower));
  }
  const double k = static_cast<double>(velocities.size());
  double mean = 0.0, half = 0.0;
  for (std::size_t i = 0; i < velocities.size(); ++i) {
    mean += velocities[i] / k;
    half += halves[i] / k;
  }
  double var = 0.0;
  for (const double v : velocities) var += (v - mean) * (v - mean) / (k - 1.0);
  const double ratio = half / (1.96 * std::sqrt(var));
  EXPECT_GT(ratio, 0.6) << "mean half-width " << half << " m/s against an sd of " << std::sqrt(var) << " m/s";
  EXPECT_LT(ratio, 2.5) << "mean half-width " << half << " m/s against an sd of " << std::sqrt(var) << " m/s";
  // And each interval covers the records' mean velocity as a 95 % interval
  // should: at least 13 of 16 (P(fewer) < 0.01 at a coverage of 0.95).
  for (std::size_t i = 0; i < velocities.size(); ++i) {
    covering += std::abs(velocities[i] - mean) <= halves[i] ? 1 : 0;
  }
  EXPECT_GE(covering, 13);
}

}  // namespace
