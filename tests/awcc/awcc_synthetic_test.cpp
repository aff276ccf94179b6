// AWCC against the synthetic probe's truth.
#include <gtest/gtest.h>

#include <cmath>

#include "awcc/awcc.hpp"
#include "clean_scene.hpp"
#include "synth/synthesiser.hpp"

namespace {

TEST(AwccSynthetic, RecoversMeanAndTurbulenceWhereTheErrorMechanismsVanish) {
  // The clean scene (clean_scene.hpp; its 1 s time scale against windows of
  // ~10 ms): the estimate must sit within 1 % (mean) and 10 % (Tu) of the
  // realised truth of the same series.
  const synth::Scene s = pdp_test::clean_scene(60.0);
  synth::SynthesisOptions so;
  so.keep_velocity_history = true;
  const auto syn = synth::synthesise(s, so);
  const auto r = awcc::awcc(syn.signals[0], syn.signals[1], s.dx, {});
  ASSERT_TRUE(r.ok()) << r.message;
  const auto& truth = syn.truth.realised;
  EXPECT_NEAR(r.velocity / truth.mean_velocity[0], 1.0, 0.01);
  EXPECT_NEAR(r.turbulence_intensity / truth.turbulence_intensity[0], 1.0, 0.10);
  EXPECT_GT(r.windows_accepted, r.windows_total * 9 / 10);

  // Window velocities track the window-averaged truth: the differences are
  // lag quantisation (1 sample of 250, 0.4 %) and the velocity change during
  // the tip-to-tip transit; allow an rms of 1.5 % and demand a correlation
  // above 0.9 with the truth's window-to-window fluctuation (sd 5 %).
  double sum_d2 = 0, su = 0, st = 0, suu = 0, stt = 0, sut = 0;
  double n = 0;
  for (const auto& w : r.windows) {
    if (w.fate != awcc::WindowFate::accepted) continue;
    const double t = syn.history->mean_velocity(w.start_time, w.start_time + w.duration);
    sum_d2 += (w.velocity - t) * (w.velocity - t);
    su += w.velocity;
    st += t;
    suu += w.velocity * w.velocity;
    stt += t * t;
    sut += w.velocity * t;
    ++n;
  }
  const double rms = std::sqrt(sum_d2 / n);
  const double corr = (sut / n - su / n * st / n) /
                      std::sqrt((suu / n - su * su / (n * n)) * (stt / n - st * st / (n * n)));
  EXPECT_LT(rms / truth.mean_velocity[0], 0.015);
  EXPECT_GT(corr, 0.9);
}

TEST(AwccSynthetic, BothCorrelationPathsGiveTheSameWindowsOnSyntheticData) {
  synth::Scene s;
  s.duration = 2.0;
  const auto syn = synth::synthesise(s);
  awcc::AwccOptions a, b;
  a.path = awcc::CorrelationPath::intervals;
  b.path = awcc::CorrelationPath::fft;
  const auto ra = awcc::awcc(syn.signals[0], syn.signals[1], s.dx, a);
  const auto rb = awcc::awcc(syn.signals[0], syn.signals[1], s.dx, b);
  ASSERT_EQ(ra.windows.size(), rb.windows.size());
  ASSERT_GT(ra.windows.size(), 200u);
  for (std::size_t i = 0; i < ra.windows.size(); ++i) {
    EXPECT_EQ(ra.windows[i].lag_samples, rb.windows[i].lag_samples) << i;
    EXPECT_NEAR(ra.windows[i].r12_max, rb.windows[i].r12_max, 1e-9) << i;
    EXPECT_NEAR(ra.windows[i].spr, rb.windows[i].spr, 1e-6) << i;
  }
  EXPECT_EQ(ra.windows_accepted, rb.windows_accepted);
}

struct Extreme {
  const char* name;
  void (*apply)(synth::Scene&);
};

class AwccExtreme : public ::testing::TestWithParam<Extreme> {};

// METHOD 5's corners: each finishes with finite results or a stated reason.
TEST_P(AwccExtreme, FinishesWithFiniteResultsOrAReason) {
  synth::Scene s;
  s.duration = 2.0;
  GetParam().apply(s);
  ASSERT_TRUE(s.validate().ok()) << s.validate().message;
  const auto syn = synth::synthesise(s);
  const auto r = awcc::awcc(syn.signals[0], syn.signals[1], s.dx, {});
  for (double v : {r.velocity, r.velocity_rms, r.turbulence_intensity, r.velocity_ci95.lower, r.velocity_ci95.upper,
                   r.turbulence_intensity_ci95.lower, r.turbulence_intensity_ci95.upper}) {
    EXPECT_TRUE(std::isfinite(v)) << GetParam().name;
  }
  if (r.ok()) {
    EXPECT_GT(r.velocity, 0.0);
    EXPECT_GE(r.windows_accepted, 2);
  } else {
    EXPECT_FALSE(r.message.empty()) << GetParam().name;
  }
  for (const auto& w : r.windows) {
    ASSERT_TRUE(std::isfinite(w.velocity) && std::isfinite(w.r12_max) && std::isfinite(w.spr)) << GetParam().name;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Method5, AwccExtreme,
    ::testing::Values(Extreme{"NoTurbulence", [](synth::Scene& s) { s.tu = s.tu_y = s.tu_z = 0.0; }},
                      Extreme{"StrongTurbulence", [](synth::Scene& s) { s.tu = 0.35; s.tu_y = s.tu_z = 0.175; }},
                      Extreme{"LowVoidFraction", [](synth::Scene& s) { s.void_fraction = 0.005; s.duration = 20.0; }},
                      Extreme{"HighVoidFraction", [](synth::Scene& s) { s.void_fraction = 0.4; }},
                      Extreme{"SmallBubbles", [](synth::Scene& s) { s.bubble_diameter = 0.5e-3; }},
                      Extreme{"LargeBubbles", [](synth::Scene& s) { s.bubble_diameter = 20e-3; }},
                      Extreme{"CloseTips", [](synth::Scene& s) { s.dx = 0.5e-3; s.dy = 0.0; }},
                      Extreme{"FarTips", [](synth::Scene& s) { s.dx = 10e-3; }},
                      Extreme{"SlowSampling", [](synth::Scene& s) { s.fs = 10e3; }},
                      Extreme{"FastSampling", [](synth::Scene& s) { s.fs = 2e6; s.duration = 0.5; }},
                      Extreme{"SlowFlow", [](synth::Scene& s) { s.velocity = 1.0; s.duration = 10.0; }},
                      Extreme{"FastFlowSlowSampling", [](synth::Scene& s) { s.velocity = 50.0; s.fs = 10e3; }}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

}  // namespace
