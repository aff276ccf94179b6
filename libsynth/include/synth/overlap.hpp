#pragma once
// The volume two overlapping particles share, which the synthesiser's
// placement gives back to the flow when it must place a particle overlapping
// (synth/synthesiser.hpp, "Dense placement").

#include <algorithm>
#include <cmath>
#include <numbers>

namespace synth {

/// Volume of the intersection of two spheres of radii r1 and r2 whose
/// centres are d apart (the lens), m^3 for m:
///
///   V = pi (r1 + r2 - d)^2 (d^2 + 2 d (r1 + r2) - 3 (r1 - r2)^2) / (12 d)
///
/// for |r1 - r2| < d < r1 + r2: the sum of the two spherical caps cut by the
/// radical plane, which sits at x1 = (d^2 + r1^2 - r2^2) / (2 d) from the
/// first centre; a cap of height h on a sphere of radius r holds
/// pi h^2 (3 r - h) / 3, with h1 = r1 - x1 and h2 = r2 - (d - x1). No
/// overlap (d >= r1 + r2) gives 0; one sphere inside the other (d <= |r1 -
/// r2|) the smaller sphere's volume. Ellipsoids of one shape are spheres of
/// radius d_b / 2 in the space scaled by 1 / x_factor streamwise and
/// 1 / lateral_factor across (their product is 1: the map keeps volumes), so
/// the formula there is their shared volume exactly.
[[nodiscard]] inline double lens_volume(double r1, double r2, double d) {
  const double sum = r1 + r2;
  if (d >= sum) return 0.0;
  const double r_min = std::min(r1, r2);
  if (d <= std::fabs(r1 - r2)) return 4.0 / 3.0 * std::numbers::pi * r_min * r_min * r_min;
  const double gap = sum - d;
  const double diff = r1 - r2;
  return std::numbers::pi * gap * gap * (d * d + 2.0 * d * sum - 3.0 * diff * diff) / (12.0 * d);
}

}  // namespace synth
