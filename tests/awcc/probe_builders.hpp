#pragma once
// Multi-tip probes for the tests: a leading tip at the origin and trailing
// tips on a cone around the x axis, whose conditioning |det A_0| is known in
// closed form.

#include <cmath>
#include <numbers>
#include <vector>

#include "awcc/probe_geometry.hpp"

namespace pdp_test {

/// The leading tip at the origin and `trailing` tips at (dx, r cos phi_k,
/// r sin phi_k), phi_k = 2 pi k / trailing + phase: lengths in m.
inline std::vector<awcc::Vec3> cone_probe(int trailing, double dx, double r, double phase = 0.0) {
  std::vector<awcc::Vec3> tips{{0.0, 0.0, 0.0}};
  for (int k = 0; k < trailing; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / trailing + phase;
    tips.push_back({dx, r * std::cos(phi), r * std::sin(phi)});
  }
  return tips;
}

/// |det A_0| of three tips of a cone at 120 degrees: the unit vectors
/// (cos a, sin a cos phi_k, sin a sin phi_k), tan a = r / dx, have det
/// cos a sin^2 a (3 sqrt(3) / 2).
inline double three_tip_cone_conditioning(double dx, double r) {
  const double a = std::atan2(r, dx);
  return std::cos(a) * std::sin(a) * std::sin(a) * 1.5 * std::sqrt(3.0);
}

/// The cone half-angle a whose three-tip conditioning is `det` (the root
/// below the maximum at tan a = sqrt 2), by bisection.
inline double cone_angle_for(double det) {
  double lo = 0.0, hi = std::atan(std::sqrt(2.0));
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (three_tip_cone_conditioning(std::cos(mid), std::sin(mid)) < det ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace pdp_test
