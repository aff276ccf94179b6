#pragma once
// Closed-form pieces of the error mechanisms of a dual-tip probe (METHOD.md 6).
// Angles in radians; the trajectory angle theta = atan(u_y / u_x) lies in the
// x-y plane, the tip axis angle alpha = atan(dy / dx).

#include <cmath>
#include <numbers>

namespace synth {

/// Tip axis angle alpha = atan2(dy, dx), rad.
inline double tip_axis_angle(double dx, double dy) { return std::atan2(dy, dx); }

/// Trajectory angle theta = atan2(u_y, u_x), rad.
inline double trajectory_angle(double u_x, double u_y) { return std::atan2(u_y, u_x); }

struct AngleInterval {
  double lower = 0.0;  ///< rad
  double upper = 0.0;  ///< rad
  [[nodiscard]] bool contains(double theta) const { return theta > lower && theta < upper; }
};

/// E1, selective sampling: a bubble of diameter d pierced by the leading tip is
/// also pierced by the trailing tip only if its trajectory angle lies within
/// asin(d / S) of the tip axis angle, S = sqrt(dx^2 + dy^2). When d >= S every
/// forward angle (-pi/2, pi/2) qualifies.
inline AngleInterval detection_angle_interval(double dx, double dy, double d) {
  const double s = std::hypot(dx, dy);
  const double alpha = tip_axis_angle(dx, dy);
  if (d >= s) return {-std::numbers::pi / 2.0, std::numbers::pi / 2.0};
  const double half = std::asin(d / s);
  return {alpha - half, alpha + half};
}

/// E2, velocity bias of oblique impacts (Thorwarth 2008): the ratio of the
/// estimated streamwise velocity dx / tau to the true one,
/// chi = cos(alpha) / (cos(theta) cos(theta - alpha)).
inline double velocity_bias_ratio(double alpha, double theta) {
  return std::cos(alpha) / (std::cos(theta) * std::cos(theta - alpha));
}

/// E4, window averaging: the mean duration of an AWCC window of Np particles,
/// T_W = Np d / (1.5 u c) (spheres), s.
inline double window_duration(double np, double d, double u, double c) { return np * d / (1.5 * u * c); }

}  // namespace synth
