// The bubble-probe interaction correction (awcc/probe_correction.hpp): its
// force terms against values computed by hand, its integrator against a
// closed form, the root condition at the answer, and its behaviour.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "awcc/probe_correction.hpp"

namespace {

using awcc::ProbeCorrectionOptions;
namespace detail = awcc::detail;

TEST(ProbeCorrection, DragCoefficientInEachOfTomiyamasRegimes) {
  const ProbeCorrectionOptions o;
  // d 2 mm, 0.2 m/s: Re 400, 24/Re (1 + 0.15 Re^0.687) = 0.6124, 72/Re = 0.18,
  // Eo = 9.81 x 996.88 x 4e-6 / 0.073 = 0.5359: 8/3 Eo/(Eo + 4) = 0.31503 wins.
  EXPECT_NEAR(detail::drag_coefficient(0.2, 2e-3, o), 0.31503469544657015, 1e-14);
  // d 0.5 mm, 1 cm/s: Re 5, the viscous branch 24/5 (1 + 0.15 x 5^0.687) = 6.9753.
  EXPECT_NEAR(detail::drag_coefficient(0.01, 0.5e-3, o), 6.975328698501657, 1e-13);
  // d 5 mm, 0.5 m/s: Re 2500; 72/Re = 0.0288; Eo = 3.35: 8/3 x 3.35/7.35 = 1.21524.
  EXPECT_NEAR(detail::drag_coefficient(0.5, 5e-3, o), 1.2152431824632055, 1e-13);
  EXPECT_EQ(detail::drag_coefficient(0.0, 2e-3, o), 0.0);  // no relative motion, no drag
}

TEST(ProbeCorrection, DeformationCoefficientAndTheForceBalance) {
  const ProbeCorrectionOptions o;
  // Rb = 2e-3 x 3 / 1e-6 = 6000: -7.2e-8 x 3.6e7 + 0.002 x 6000 - 0.589 = 8.819.
  EXPECT_NEAR(detail::deformation_coefficient(3.0, 2e-3, o), 8.819, 1e-12);
  EXPECT_EQ(detail::deformation_coefficient(0.1, 1e-3, o), 0.0);  // Rb 100: negative, clipped to 0
  // d 2 mm at 3 m/s in a carrier at 3.2 m/s, 45 deg, needle 0.6 mm: drag
  // +9.430, buoyancy -13.827, contact -65.684, impact -0.680, deformation
  // -445.555 m/s2 (each written out independently): -516.316 m/s2.
  EXPECT_NEAR(detail::bubble_acceleration(3.0, 2e-3, 3.2, o), -516.31638924139, 1e-9);
}

TEST(ProbeCorrection, TheIntegratorMatchesTheClosedFormOfQuadraticDrag) {
  // du/dt = -k (u - uc)^2 (constant C_D, drag only, u > uc):
  // u(t) = uc + v0 / (1 + k v0 t), v0 = u(0) - uc.
  const double k = 250.0, uc = 2.0, u0 = 3.5, t1 = 4e-3;
  const auto u = detail::integrate_velocity([&](double v) { return -k * (v - uc) * (v - uc); }, u0, t1, 1e-13, 20000);
  ASSERT_TRUE(u);
  const double exact = uc + (u0 - uc) / (1.0 + k * (u0 - uc) * t1);
  EXPECT_NEAR(*u, exact, 1e-11 * exact);
  // A bubble that stops: du/dt = -1000 m/s2 from 1 m/s stops at 1 ms.
  EXPECT_FALSE(detail::integrate_velocity([](double) { return -1000.0; }, 1.0, 2e-3, 1e-12, 20000));
  EXPECT_TRUE(detail::integrate_velocity([](double) { return -1000.0; }, 1.0, 0.5e-3, 1e-12, 20000));
}

TEST(ProbeCorrection, TheRootConditionHoldsAtTheAnswer) {
  const ProbeCorrectionOptions o;
  const double um = 3.3, c = 0.08, f = 90.0, dx = 7.15e-3;
  const auto r = awcc::correct_window(um, c, f, dx, o);
  ASSERT_EQ(r.outcome, awcc::CorrectionOutcome::corrected) << r.why;
  EXPECT_GT(r.velocity, um);
  // u0 + u(T1; u0) = 2 u_m, recomputed from the model at the answer.
  const double d = 1.5 * r.velocity * c / f;
  const double carrier = r.velocity - detail::rise_velocity(d, o);
  const auto exit = detail::integrate_velocity([&](double u) { return detail::bubble_acceleration(u, d, carrier, o); },
                                               r.velocity, dx / um, 1e-13, o.max_steps);
  ASSERT_TRUE(exit);
  EXPECT_LE(std::fabs(r.velocity + *exit - 2.0 * um), 1e-9 * um);
}

TEST(ProbeCorrection, SmallerBubblesAndThickerNeedlesAreCorrectedMore) {
  ProbeCorrectionOptions o;
  const double um = 3.0, dx = 5e-3;
  // d = 1.5 u0 C / F: the same C with a larger F is a smaller bubble.
  double previous = 0.0;
  for (double f : {50.0, 100.0, 200.0, 400.0}) {
    const auto r = awcc::correct_window(um, 0.1, f, dx, o);
    ASSERT_EQ(r.outcome, awcc::CorrectionOutcome::corrected) << f << ": " << r.why;
    EXPECT_GT(r.velocity, previous) << f;
    previous = r.velocity;
  }
  previous = 0.0;
  for (double needle : {0.2e-3, 0.6e-3, 1.0e-3}) {
    o.needle_diameter = needle;
    const auto r = awcc::correct_window(um, 0.1, 100.0, dx, o);
    ASSERT_EQ(r.outcome, awcc::CorrectionOutcome::corrected) << needle << ": " << r.why;
    EXPECT_GT(r.velocity, previous) << needle;
    previous = r.velocity;
  }
}

TEST(ProbeCorrection, WindowsOutsideTheModelAreNeverSolved) {
  const ProbeCorrectionOptions o;
  // Not bubbly: as measured.
  const auto dense = awcc::correct_window(3.0, 0.45, 100.0, 5e-3, o);
  EXPECT_EQ(dense.outcome, awcc::CorrectionOutcome::not_bubbly);
  EXPECT_EQ(dense.velocity, 3.0);
  // A negative velocity (the toolbox's solver never returns on it): refused at once.
  const auto backwards = awcc::correct_window(-0.04, 0.05, 100.0, 5e-3, o);
  EXPECT_EQ(backwards.outcome, awcc::CorrectionOutcome::failed);
  EXPECT_FALSE(backwards.why.empty());
  // A crawling window: the bubble stops on the needle before the trailing tip.
  const auto crawl = awcc::correct_window(0.06, 0.0025, 17.5, 7.15e-3, o);
  EXPECT_EQ(crawl.outcome, awcc::CorrectionOutcome::failed);
  EXPECT_NE(crawl.why.find("stops"), std::string::npos);
}

TEST(ProbeCorrection, RiseVelocityIsTheDragBalanceAndTakesTheSignOfCosGamma) {
  ProbeCorrectionOptions o;
  const double d = 2e-3;
  const double ur = detail::rise_velocity(d, o);
  ASSERT_GT(ur, 0.0);
  // u_r^2 = 4 d g |cos| (rho_c - rho_d) / (3 C_D(u_r) rho_c) at the answer.
  const double cd = detail::drag_coefficient(ur, d, o);
  EXPECT_NEAR(ur * ur, 4 * d * 9.81 * std::cos(std::numbers::pi / 4) * (998 - 1.12) / (3 * cd * 998), 1e-10);
  o.probe_angle = 3 * std::numbers::pi / 4;
  EXPECT_NEAR(detail::rise_velocity(d, o), -ur, 1e-12);
  o.probe_angle = std::numbers::pi / 2;
  EXPECT_EQ(detail::rise_velocity(d, o), 0.0);
}

}  // namespace
