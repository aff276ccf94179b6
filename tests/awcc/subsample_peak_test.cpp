// Tests of awcc/subsample_peak.hpp: each estimator exact on the shape it
// assumes over the whole sub-sample phase, the undefined cases, and a planted
// fractional delay recovered by FSCC and AWCC alike.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "awcc/awcc.hpp"
#include "awcc/fscc.hpp"
#include "awcc/subsample_peak.hpp"

namespace {

using awcc::Subsample;

// The offset an estimator finds on f sampled at whole lags -20..20 (whole-sample peak
// taken as the largest sample).
template <class F>
double offset_on(Subsample method, F f) {
  std::int64_t peak = -20;
  for (std::int64_t k = -20; k <= 20; ++k)
    if (f(static_cast<double>(k)) > f(static_cast<double>(peak))) peak = k;
  return static_cast<double>(peak) +
         awcc::subsample_offset(method, [&](std::int64_t k) { return f(static_cast<double>(k)); }, peak, -20, 20);
}

// Each estimator is exact on its own peak shape at every phase of the true
// peak t within the sample (the phase sweep): the triangle on a symmetric
// triangle (the correlation of two equal rectangular pulses), the parabola on
// a parabola, the Gaussian on a Gaussian.
TEST(SubsamplePeak, EachEstimatorIsExactOnItsShapeOverThePhase) {
  for (double t = -0.5; t <= 0.5; t += 0.05) {
    const double where = 3.0 + t;
    const auto triangle = [&](double k) { return std::max(0.0, 1.0 - std::abs(k - where) / 4.0); };
    const auto parabola = [&](double k) { return 1.0 - 0.1 * (k - where) * (k - where); };
    const auto gaussian = [&](double k) { return std::exp(-(k - where) * (k - where) / 3.0); };
    EXPECT_NEAR(offset_on(Subsample::triangle, triangle), where, 1e-12) << t;
    EXPECT_NEAR(offset_on(Subsample::parabolic, parabola), where, 1e-12) << t;
    EXPECT_NEAR(offset_on(Subsample::gaussian, gaussian), where, 1e-12) << t;
    // Whole samples round to the nearest lag: an error up to half a sample.
    EXPECT_LE(std::abs(offset_on(Subsample::none, triangle) - where), 0.5 + 1e-12) << t;
  }
}

// The parabola through a cusp locks toward the sample (the reason the
// triangle is the default): on a triangle of half-width 4 at phase 0.25 it
// finds 1/6, not 0.25 (delta = (r- - r+) / (2 (r- - 2 r0 + r+)) with
// r- = 0.6875, r0 = 0.9375, r+ = 0.8125: -0.125 / -0.75).
TEST(SubsamplePeak, TheParabolaLocksTowardTheSampleOnACusp) {
  const auto triangle = [](double k) { return std::max(0.0, 1.0 - std::abs(k - 0.25) / 4.0); };
  const double r_minus = triangle(-1), r0 = triangle(0), r_plus = triangle(1);
  const double expected = 0.5 * (r_minus - r_plus) / (r_minus - 2 * r0 + r_plus);
  EXPECT_NEAR(offset_on(Subsample::parabolic, triangle), expected, 1e-12);
  EXPECT_NEAR(expected, 1.0 / 6.0, 1e-15);
}

// The centroid of a peak symmetric about a whole lag is that lag; on a
// symmetric triangle about a fractional lag it lies between the sample and
// the truth.
TEST(SubsamplePeak, CentroidOfASymmetricPeak) {
  const auto symmetric = [](double k) { return std::max(0.0, 1.0 - std::abs(k - 2.0) / 5.0); };
  EXPECT_NEAR(offset_on(Subsample::centroid, symmetric), 2.0, 1e-12);
}

TEST(SubsamplePeak, UndefinedCasesGiveTheWholeSample) {
  const auto flat = [](std::int64_t) { return 0.5; };
  for (auto m : {Subsample::parabolic, Subsample::gaussian, Subsample::triangle, Subsample::centroid}) {
    EXPECT_EQ(awcc::subsample_offset(m, flat, 0, -3, 3), 0.0) << awcc::to_string(m);
    // At the ends of the lags searched there is no neighbour on one side.
    const auto rising = [](std::int64_t k) { return static_cast<double>(k); };
    EXPECT_EQ(awcc::subsample_offset(m, rising, 3, -3, 3), 0.0) << awcc::to_string(m);
    EXPECT_EQ(awcc::subsample_offset(m, rising, -3, -3, 3), 0.0) << awcc::to_string(m);
  }
  const auto peaked = [](std::int64_t k) { const double x = static_cast<double>(k);
    return 1.0 - 0.1 * x * x + 0.01 * x;
  };
  EXPECT_EQ(awcc::subsample_offset(Subsample::none, peaked, 0, -3, 3), 0.0);
  // A Gaussian fit needs positive values: with a negative neighbour it is the parabola's.
  EXPECT_DOUBLE_EQ(awcc::detail::gaussian_offset(-0.1, 0.5, 0.3), awcc::detail::parabolic_offset(-0.1, 0.5, 0.3));
}

// Two tips seeing the same bubbles, the trailing one `delay` samples later
// (a fraction of a sample): drawn at 1,000 times the rate and sampled, as a
// probe samples continuous interfaces.
struct PlantedPair {
  awcc::AirIntervals leading, trailing;
};

PlantedPair planted_pair(double delay, std::uint64_t seed) {
  constexpr double fs = 20e3;
  constexpr std::int64_t n = 2'000'000;  // 100 s
  std::mt19937_64 rng(seed);
  std::exponential_distribution<double> gap(1.0 / 60.0);   // water between bubbles, samples
  std::uniform_real_distribution<double> chord(8.0, 30.0);  // air chords, samples
  PlantedPair p;
  p.leading.fs = p.trailing.fs = fs;
  p.leading.sample_count = p.trailing.sample_count = n;
  double t = 10.0;
  for (;;) {
    const double start = t + gap(rng), end = start + chord(rng);
    if (end + delay + 2 >= static_cast<double>(n)) break;
    // Sample i is air when the interface times bracket it (start < i < end).
    auto sampled = [](double a, double b) {
      return awcc::AirInterval{static_cast<std::int64_t>(std::floor(a)) + 1, static_cast<std::int64_t>(std::ceil(b))};
    };
    const auto lead = sampled(start, end), trail = sampled(start + delay, end + delay);
    if (lead.stop > lead.start) p.leading.intervals.push_back(lead);
    if (trail.stop > trail.start) p.trailing.intervals.push_back(trail);
    t = end + 1.0;
  }
  return p;
}

// A planted delay of 7.0-7.9 samples at 20 kHz (dx 5 mm: 13.7-12.7 m/s): FSCC
// and AWCC with the triangle recover it to 0.02 sample at every phase, where
// whole samples are off by up to half a sample. 0.02: the edges of each
// bubble are rounded independently (a uniform error of 1/sqrt(12) sample per
// edge); the record's correlation averages some 20,000 bubbles, so the
// scatter of its peak is far below 0.01 sample, and AWCC's windows of 10
// bubbles average to the same over 2,000 windows.
TEST(SubsamplePeak, PlantedFractionalDelayRecoveredByFsccAndAwcc) {
  constexpr double dx = 5e-3, fs = 20e3;
  for (double phase = 0.0; phase < 0.95; phase += 0.3) {
    const double delay = 7.0 + phase;
    const auto p = planted_pair(delay, 11 + static_cast<std::uint64_t>(phase * 10));
    awcc::FsccOptions f;
    f.subsample = Subsample::triangle;
    const auto r = awcc::fscc(p.leading, p.trailing, dx, f);
    ASSERT_EQ(r.status, awcc::FsccStatus::ok) << r.message;
    EXPECT_NEAR(r.lag * fs, delay, 0.02) << "FSCC, planted " << delay;
    f.subsample = Subsample::none;
    EXPECT_NEAR(awcc::fscc(p.leading, p.trailing, dx, f).lag * fs, std::round(delay), 1e-9);
    for (auto path : {awcc::CorrelationPath::intervals, awcc::CorrelationPath::fft}) {
      awcc::AwccOptions a;
      a.subsample = Subsample::triangle;
      a.path = path;
      const auto w = awcc::awcc(p.leading, p.trailing, dx, a);
      ASSERT_TRUE(w.ok()) << w.message;
      // The windows' mean lag (the mean velocity is biased low by the lags'
      // scatter: E[1 / lag] > 1 / E[lag]).
      double lags = 0.0;
      int accepted = 0;
      for (const auto& window : w.windows) {
        if (window.fate != awcc::WindowFate::accepted) continue;
        lags += window.lag * fs;
        ++accepted;
      }
      ASSERT_GT(accepted, 1000);
      EXPECT_NEAR(lags / accepted, delay, 0.02) << "AWCC, planted " << delay;
      // Every window's lag scatters about the truth instead of sitting on one sample.
      EXPECT_GT(w.turbulence_intensity, 0.0);
    }
  }
}

}  // namespace
