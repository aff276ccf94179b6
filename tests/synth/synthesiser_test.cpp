#include "synth/synthesiser.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "synth/sidecar.hpp"

namespace {

using synth::Scene;
using synth::Synthesis;
using synth::SynthesisOptions;

Synthesis run(const Scene& s, SynthesisOptions o = {}) { return synth::synthesise(s, o); }

// Exact piercing against the dense per-sample test. Both place the same
// bubbles on the same path; they may differ only where a sample falls on a
// bubble surface to rounding, which we check through the brute-force form
// |(x_tip - x_k)/a|^2 (1 on the surface).
void expect_matches_brute_force(const Scene& s, std::int64_t min_chords = 20) {
  SynthesisOptions o;
  o.keep_reference_data = true;
  const Synthesis out = run(s, o);
  ASSERT_TRUE(out.reference);
  const auto forms = synth::brute_force_distances(s, *out.reference);
  ASSERT_EQ(forms.size(), out.signals.size());
  for (std::size_t j = 0; j < forms.size(); ++j) {
    EXPECT_TRUE(out.signals[j].check().empty()) << out.signals[j].check();
    const auto dense = awcc::to_dense(out.signals[j]);
    std::int64_t mismatches = 0, air = 0;
    for (std::size_t n = 0; n < dense.size(); ++n) {
      const bool brute = forms[j][n] < 1.0;
      air += brute;
      if (brute != (dense[n] != 0)) {
        ++mismatches;
        EXPECT_NEAR(forms[j][n], 1.0, 1e-9) << "tip " << j << " sample " << n;
      }
    }
    EXPECT_LE(mismatches, 2) << "tip " << j;
    EXPECT_GE(static_cast<std::int64_t>(out.signals[j].intervals.size()), min_chords) << "tip " << j;
    EXPECT_GT(air, 0);
  }
}

Scene short_scene() {
  Scene s;
  s.duration = 0.2;
  s.fs = 100e3;
  return s;
}

TEST(ExactPiercing, MatchesBruteForceOnTheBaseCase) { expect_matches_brute_force(short_scene()); }

TEST(ExactPiercing, MatchesBruteForceWithNegativeVelocities) {
  Scene s;
  s.velocity = 1.0;
  s.tu = 0.35;
  s.tu_y = s.tu_z = 0.175;
  s.time_scale = 1e-3;
  s.duration = 3.0;
  s.fs = 50e3;
  s.bubble_diameter = 2e-3;
  s.dx = 2e-3;
  s.dy = 0.0;
  SynthesisOptions o;
  o.keep_reference_data = true;
  const auto out = run(s, o);
  const double min_u = std::min_element(out.reference->velocities.begin(), out.reference->velocities.end(),
                                        [](auto& a, auto& b) { return a.x < b.x; })->x;
  ASSERT_LT(min_u, 0.0) << "the scene must contain flow reversals";
  EXPECT_EQ(out.truth.reentries_missed, 0);
  expect_matches_brute_force(s);
}

// Flow that reverses often and for long (Tu_x = 1): bubbles pass a tip, are
// carried back over it and pass it again, many velocity steps after they
// first left it. The pierce walk passes over blocks of steps that cannot
// bring a bubble back (Synthesiser::walk); a block skipped wrongly loses
// those later pierces, which the brute-force test sees.
TEST(ExactPiercing, MatchesBruteForceWhenBubblesPassATipAgainLater) {
  Scene s;
  s.velocity = 0.5;
  s.tu = 1.0;
  s.tu_y = s.tu_z = 0.5;
  s.time_scale = 0.01;
  s.duration = 2.0;
  s.fs = 20e3;
  s.bubble_diameter = 2e-3;
  s.dx = 2e-3;
  s.dy = 0.0;
  SynthesisOptions o;
  o.bubble_truth = true;
  const auto out = run(s, o);
  ASSERT_TRUE(out.bubbles);
  const auto& passes = out.bubbles->extra_passes;
  ASSERT_GT(std::count_if(passes.begin(), passes.end(), [](std::int32_t n) { return n > 0; }), 20)
      << "the scene must carry bubbles back over a tip";
  expect_matches_brute_force(s);
}

TEST(ExactPiercing, MatchesBruteForceForEllipsoidsAndLogNormalSizes) {
  for (double aspect : {0.5, 2.0}) {
    Scene s = short_scene();
    s.aspect_ratio = aspect;
    s.diameter_log_sd = 0.3;
    SCOPED_TRACE(aspect);
    expect_matches_brute_force(s);
  }
}

TEST(ExactPiercing, MatchesBruteForceForAFourTipProbeAndPoissonArrivals) {
  Scene s = short_scene();
  s.tips = {{0, 0, 0}, {5e-3, 0, 0}, {5e-3, 1.5e-3, 0}, {5e-3, 0, 1.5e-3}};
  s.arrival = synth::ArrivalRule::poisson_time;
  expect_matches_brute_force(s);
  const auto out = run(s);
  EXPECT_EQ(out.truth.pairs.size(), 6u);
  for (const auto& p : out.truth.pairs) {
    EXPECT_LE(p.pierced_by_both, std::min(out.truth.tips[static_cast<std::size_t>(p.first)].bubbles_pierced,
                                          out.truth.tips[static_cast<std::size_t>(p.second)].bubbles_pierced));
  }
}

TEST(ExactPiercing, MatchesBruteForceWithSpaceArrivalsAndASlowStep) {
  Scene s = short_scene();
  s.arrival = synth::ArrivalRule::poisson_space;
  s.realisation_step = 2e-4;  // coarser than the transit: pieces span tips
  expect_matches_brute_force(s);
}

// The spray region: droplets at 1 - c, air outside them. The brute-force
// form is the air form there too (f < 1 air, synthesiser.hpp), so the same
// comparison holds sample by sample; log-normal ellipsoids and a
// turbulent flow with Poisson arrivals at c = 0.7, the base case at 0.9.
TEST(ExactPiercing, MatchesBruteForceInTheSprayRegion) {
  Scene s = short_scene();
  s.void_fraction = 0.9;
  expect_matches_brute_force(s);
  s.void_fraction = 0.7;
  s.aspect_ratio = 0.6;
  s.diameter_log_sd = 0.3;
  s.arrival = synth::ArrivalRule::poisson_time;
  expect_matches_brute_force(s);
  const auto out = run(s, [] {
    SynthesisOptions o;
    o.keep_reference_data = true;
    return o;
  }());
  // The dense reference signal is the same function of the samples.
  const auto dense = synth::brute_force_signals(s, *out.reference);
  for (std::size_t j = 0; j < dense.size(); ++j) {
    const auto exact = awcc::to_dense(out.signals[j]);
    std::size_t differ = 0, air = 0;
    for (std::size_t n = 0; n < exact.size(); ++n) {
      differ += exact[n] != dense[j][n];
      air += dense[j][n];
    }
    EXPECT_LE(differ, 2u) << "tip " << j;
    EXPECT_GT(static_cast<double>(air) / static_cast<double>(exact.size()), 0.5) << "tip " << j;
  }
}

// Void fraction at a tip. With arrivals equally spaced along the flow and no
// turbulence the tip sees c exactly in expectation. Chords are independent:
// the tip's air time is a sum over N pierced bubbles of chord times t_k, with
// N binomial (probability p = pi r^2 / A per entering bubble) and chords
// through a sphere at a uniform offset, CV^2 = 1/8. So
//   Var(c_hat) / c^2 ~ ((1 - p) + 1/8) / N  <  1.15 / N.
// We run long enough for 4 standard errors to stay below 2 % (N >= 46,000),
// then demand both.
class VoidFraction : public ::testing::TestWithParam<double> {};

TEST_P(VoidFraction, RealisedWithinTwoPercentAndPierceRateMatches) {
  Scene s;
  s.void_fraction = GetParam();
  s.tu = s.tu_y = s.tu_z = 0.0;
  s.arrival = synth::ArrivalRule::equal_space;
  s.bubble_diameter = 1e-3;
  s.fs = 200e3;
  s.realisation_step = 1e-3;  // the path is exact at any step without turbulence
  const double rate = 1.5 * s.void_fraction * s.velocity / s.bubble_diameter;
  s.duration = std::ceil(50'000.0 / rate);
  const auto out = run(s);
  EXPECT_NEAR(out.truth.expected_pierce_rate, rate, 1e-9 * rate);
  for (const auto& tip : out.truth.tips) {
    const double n = static_cast<double>(tip.bubbles_pierced);
    const double tolerance = 4.0 * std::sqrt(1.15 / n);
    ASSERT_LT(tolerance, 0.02);
    EXPECT_NEAR(tip.void_fraction / s.void_fraction, 1.0, tolerance) << "c = " << s.void_fraction;
    // Pierces are binomial: relative SE sqrt((1 - p) / N) < sqrt(1 / N).
    EXPECT_NEAR(n / s.duration / rate, 1.0, 4.0 / std::sqrt(n)) << "c = " << s.void_fraction;
  }
}

INSTANTIATE_TEST_SUITE_P(C, VoidFraction, ::testing::Values(0.005, 0.05, 0.25, 0.4));

TEST(Determinism, ChunkSizeDoesNotChangeAnything) {
  Scene s = short_scene();
  s.duration = 0.5;
  SynthesisOptions reference_options;
  reference_options.chunk_steps = 1 << 20;
  const auto reference = run(s, reference_options);
  const std::string reference_truth = synth::truth_to_json(reference.truth).dump();
  for (std::int64_t chunk : {1, 7, 4096}) {
    SynthesisOptions o;
    o.chunk_steps = chunk;
    const auto out = run(s, o);
    ASSERT_EQ(out.signals.size(), reference.signals.size());
    for (std::size_t j = 0; j < out.signals.size(); ++j) {
      EXPECT_EQ(out.signals[j].intervals, reference.signals[j].intervals) << "chunk " << chunk;
    }
    EXPECT_EQ(synth::truth_to_json(out.truth).dump(), reference_truth) << "chunk " << chunk;
  }
  // And the seed matters.
  s.seed = 99;
  EXPECT_NE(run(s).signals[0].intervals, reference.signals[0].intervals);
}

TEST(VelocityHistory, WindowAveragesEqualTheIntegralOfTheSteps) {
  Scene s = short_scene();
  SynthesisOptions o;
  o.keep_velocity_history = true;
  o.keep_reference_data = true;
  const auto out = run(s, o);
  ASSERT_TRUE(out.history);
  const auto& ref = *out.reference;
  const double dt = ref.step;
  const auto first = static_cast<std::size_t>(std::llround(-ref.t_start / dt));  // step at t = 0
  // Brute-force integral of the piecewise-constant u_x over [t0, t1).
  auto integral = [&](double t0, double t1) {
    long double sum = 0;
    for (std::size_t k = first; k < ref.velocities.size(); ++k) {
      const double a = (static_cast<double>(k - first)) * dt, b = a + dt;
      const double lo = std::max(a, t0), hi = std::min(b, t1);
      if (hi > lo) sum += ref.velocities[k].x * (hi - lo);
    }
    return static_cast<double>(sum);
  };
  for (auto [t0, t1] : {std::pair{0.0, 0.2}, {0.013, 0.0131}, {0.05, 0.0537}, {0.1, 0.19999}}) {
    EXPECT_NEAR(out.history->mean_velocity(t0, t1), integral(t0, t1) / (t1 - t0), 1e-9) << t0 << " " << t1;
  }
  EXPECT_NEAR(out.history->mean_velocity(0.0, s.duration), out.truth.realised.mean_velocity[0], 1e-9);
}

// The history is kept in blocks of 2^20 steps; a window across a block's
// end must read the same displacements as one array would. X_k = k^2 / 8 is
// exact in double up to 2^26 steps, so every answer below is exact: the
// interpolated displacement at t = (k + f) step is X_k + (X_{k+1} - X_k) f,
// and the mean over [k, m) steps is (X_m - X_k) / ((m - k) step).
TEST(VelocityHistory, AWindowAcrossABlocksEndReadsBothBlocks) {
  const std::size_t block = std::size_t{1} << 20;
  const std::size_t n = 2 * block + 5;
  auto x = [](std::size_t k) { return static_cast<double>(k) * static_cast<double>(k) / 8.0; };
  std::vector<double> all(n);
  synth::VelocityHistory stepwise(0.5);  // X_0 = 0 pushed by the constructor
  for (std::size_t k = 0; k < n; ++k) {
    all[k] = x(k);
    if (k > 0) stepwise.push_back(x(k));
  }
  const synth::VelocityHistory whole(0.5, all);
  for (const synth::VelocityHistory* h : {static_cast<const synth::VelocityHistory*>(&stepwise), &whole}) {
    EXPECT_DOUBLE_EQ(h->end_time(), 0.5 * static_cast<double>(n - 1));
    EXPECT_EQ(h->back(), x(n - 1));
    for (const std::size_t k : {block - 2, block - 1, block, block + 1, 2 * block - 1, 2 * block, n - 2}) {
      const double t = 0.5 * static_cast<double>(k);
      EXPECT_EQ(h->displacement(t), x(k)) << k;
      EXPECT_EQ(h->displacement(t + 0.25), x(k) + (x(k + 1) - x(k)) * 0.5) << k;
      // The velocity at a step: (X_{k+1} - X_k) / step.
      EXPECT_EQ(h->mean_velocity(t, t), (x(k + 1) - x(k)) / 0.5) << k;
    }
    // A window from one block into the next.
    const double t0 = 0.5 * static_cast<double>(block - 3), t1 = 0.5 * static_cast<double>(block + 4);
    EXPECT_EQ(h->mean_velocity(t0, t1), (x(block + 4) - x(block - 3)) / (t1 - t0));
  }
}

// Extreme corners of METHOD 5's ranges: each must run and give sane truth.
// Bounds: the realised mean is within 5 standard errors sigma sqrt(2T/D) of
// the imposed one (D >> T); the pierce count of each tip within 5 binomial
// standard errors of the equal-time expectation rate * (1 + Tu^2) (the tip
// sees c (1 + Tu_x^2) when arrivals are equal in time, METHOD 5.2).
struct Extreme {
  const char* name;
  void (*apply)(Scene&);
};

class ExtremeScene : public ::testing::TestWithParam<Extreme> {};

TEST_P(ExtremeScene, RunsAndGivesSaneTruth) {
  Scene s;
  s.duration = 10.0;
  s.fs = 100e3;
  GetParam().apply(s);
  ASSERT_TRUE(s.validate().ok()) << s.validate().message;
  const auto out = run(s);
  const auto& t = out.truth;
  EXPECT_EQ(t.reentries_missed, 0);
  const auto& r = t.realised;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(std::isfinite(r.mean_velocity[static_cast<std::size_t>(i)]));
    ASSERT_TRUE(std::isfinite(r.turbulence_intensity[static_cast<std::size_t>(i)]));
  }
  const double sigma = s.velocity * s.tu;
  const double se = sigma * std::sqrt(2.0 * s.time_scale / s.duration);
  EXPECT_NEAR(r.mean_velocity[0], s.velocity, 5.0 * se + 1e-12);
  if (s.tu == 0.0) {
    EXPECT_EQ(r.rms_velocity[0], 0.0);
    EXPECT_FALSE(r.integral_time_scale[0].has_value());
  } else {
    ASSERT_TRUE(r.integral_time_scale[0].has_value());
    EXPECT_GT(*r.integral_time_scale[0], 0.0);
  }
  const double expected = t.expected_pierce_rate * (1.0 + s.tu * s.tu) * s.duration;
  for (const auto& tip : t.tips) {
    EXPECT_NEAR(static_cast<double>(tip.bubbles_pierced), expected, 5.0 * std::sqrt(expected) + 0.05 * expected)
        << GetParam().name;
    EXPECT_GE(tip.void_fraction, 0.0);
    EXPECT_LT(tip.void_fraction, 1.0);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Method5, ExtremeScene,
    ::testing::Values(Extreme{"NoTurbulence", [](Scene& s) { s.tu = s.tu_y = s.tu_z = 0.0; }},
                      Extreme{"FastFlowSlowSampling", [](Scene& s) { s.velocity = 50.0; s.fs = 10e3; }},
                      Extreme{"SmallBubblesWideProbe", [](Scene& s) { s.bubble_diameter = 0.5e-3; s.dx = 10e-3; }},
                      Extreme{"ShortTimeScale", [](Scene& s) { s.time_scale = 1e-3; }},
                      Extreme{"LowVoidFraction", [](Scene& s) { s.void_fraction = 0.005; s.duration = 60.0; }},
                      Extreme{"FastSampling", [](Scene& s) { s.fs = 2e6; s.duration = 2.0; }}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(Truth, FlowStatisticsOfALongRecordMatchTheImposedOnes) {
  // 2000 integral time scales: the realised Tu has relative standard error
  // about sqrt(T / D) = 2.2 % (Var(s^2) = 2 s^4 T / D for an OU process);
  // the integral time scale (trapezoid to the first zero) about
  // sqrt(2 * 3T / D) = 5.5 %, plus a truncation bias of about -5 % (the
  // autocorrelation is cut where it meets its noise, near 3T). We allow 5
  // standard errors for Tu and rho, 25 % for T.
  Scene s;
  s.time_scale = 0.005;
  s.duration = 10.0;
  s.fs = 20e3;
  s.void_fraction = 0.01;
  const auto out = run(s);
  const auto& r = out.truth.realised;
  EXPECT_NEAR(r.turbulence_intensity[0] / s.tu, 1.0, 5 * 0.022);
  EXPECT_NEAR(r.turbulence_intensity[1] / s.tu_y, 1.0, 5 * 0.022);
  ASSERT_TRUE(r.rho_xz.has_value());
  EXPECT_NEAR(*r.rho_xz, s.rho_xz, 5 * (1 - 0.45 * 0.45) * std::sqrt(s.time_scale / s.duration));
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(r.integral_time_scale[static_cast<std::size_t>(i)].has_value());
    EXPECT_NEAR(*r.integral_time_scale[static_cast<std::size_t>(i)] / s.time_scale, 1.0, 0.25) << i;
  }
}

TEST(Synthesise, RefusesAnInvalidScene) {
  Scene s;
  s.void_fraction = 2.0;
  EXPECT_THROW(run(s), std::invalid_argument);
}

}  // namespace
