#include "synth/error_mechanisms.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

// Hand-computed values (calculator, radians).

TEST(DetectionAngleInterval, BaseCaseProbe) {
  // dx = 5 mm, dy = 1 mm, d = 3 mm: S = sqrt(26) = 5.0990195 mm,
  // alpha = atan(0.2) = 0.19739556, asin(3 / 5.0990195) = 0.62901480.
  const auto i = synth::detection_angle_interval(5e-3, 1e-3, 3e-3);
  EXPECT_NEAR(i.lower, 0.19739556 - 0.62901480, 1e-7);
  EXPECT_NEAR(i.upper, 0.19739556 + 0.62901480, 1e-7);
  EXPECT_TRUE(i.contains(0.0));
  EXPECT_FALSE(i.contains(0.9));
}

TEST(DetectionAngleInterval, AlignedTipsAreSymmetric) {
  // dy = 0, dx = 10 mm, d = 0.5 mm: +/- asin(0.05) = 0.05002086.
  const auto i = synth::detection_angle_interval(10e-3, 0.0, 0.5e-3);
  EXPECT_NEAR(i.upper, 0.05002086, 1e-8);
  EXPECT_NEAR(i.lower, -0.05002086, 1e-8);
}

TEST(DetectionAngleInterval, BubbleLargerThanSeparationSeesEveryForwardAngle) {
  const auto i = synth::detection_angle_interval(2e-3, 0.0, 5e-3);
  EXPECT_DOUBLE_EQ(i.lower, -M_PI / 2);
  EXPECT_DOUBLE_EQ(i.upper, M_PI / 2);
}

TEST(VelocityBiasRatio, HandValues) {
  // Aligned tips, straight trajectory: no bias.
  EXPECT_DOUBLE_EQ(synth::velocity_bias_ratio(0.0, 0.0), 1.0);
  // alpha = 0, theta = 0.2: 1 / cos^2(0.2) = 1 / 0.96053998 = 1.04109136.
  EXPECT_NEAR(synth::velocity_bias_ratio(0.0, 0.2), 1.04109136, 1e-8);
  // alpha = atan(0.2) = 0.19739556, theta = 0.1:
  // cos(alpha) = 0.98058068, cos(0.1) = 0.99500417, cos(-0.09739556) = 0.99526080
  // -> 0.98058068 / (0.99500417 * 0.99526080) = 0.99019683.
  EXPECT_NEAR(synth::velocity_bias_ratio(0.19739556, 0.1), 0.99019683, 1e-7);
  // theta = alpha: chi = 1 / cos(theta) ... = cos(a)/(cos(a)*1) = 1.
  EXPECT_NEAR(synth::velocity_bias_ratio(0.3, 0.3), 1.0, 1e-15);
}

TEST(WindowDuration, HandValue) {
  // Np = 10, d = 3 mm, u = 10 m/s, c = 0.25: 0.03 / 3.75 = 8 ms.
  EXPECT_NEAR(synth::window_duration(10, 3e-3, 10.0, 0.25), 8e-3, 1e-15);
}

}  // namespace
