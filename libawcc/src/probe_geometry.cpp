#include "awcc/probe_geometry.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace awcc {

namespace {

double det3(const std::array<Vec3, 3>& m) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// The inverse by the adjugate: row j of the result dotted with b is det of m
// with column j replaced by b, over det m (Cramer's rule, METHOD 11.3-11.4).
std::array<Vec3, 3> inverse3(const std::array<Vec3, 3>& m, double det) {
  if (det == 0.0) return {};
  const double f = 1.0 / det;
  return {{{f * (m[1][1] * m[2][2] - m[1][2] * m[2][1]), f * (m[0][2] * m[2][1] - m[0][1] * m[2][2]),
            f * (m[0][1] * m[1][2] - m[0][2] * m[1][1])},
           {f * (m[1][2] * m[2][0] - m[1][0] * m[2][2]), f * (m[0][0] * m[2][2] - m[0][2] * m[2][0]),
            f * (m[0][2] * m[1][0] - m[0][0] * m[1][2])},
           {f * (m[1][0] * m[2][1] - m[1][1] * m[2][0]), f * (m[0][1] * m[2][0] - m[0][0] * m[2][1]),
            f * (m[0][0] * m[1][1] - m[0][1] * m[1][0])}}};
}

// Below this the three unit vectors are in one plane with tip 0 up to the
// rounding of their coordinates (a few ulps of 1): no combination solves.
constexpr double kCoplanar = 1e-12;

}  // namespace

double TipCombination::conditioning() const { return std::fabs(det_a0); }

ProbeGeometry::ProbeGeometry(std::vector<Vec3> positions, std::optional<std::size_t> leading)
    : positions_(std::move(positions)), given_leading_(leading) {
  const std::size_t n = positions_.size();
  if (n == 0) return;
  if (leading) {
    leading_ = *leading < n ? *leading : 0;
  } else {
    leading_ = 0;
    for (std::size_t i = 1; i < n; ++i)
      if (positions_[i][0] < positions_[leading_][0]) leading_ = i;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (i != leading_) trailing_.push_back(i);
  const std::size_t k = trailing_.size();
  for (std::size_t t = 0; t < k; ++t) {
    const double d = distance(t);
    if (!(std::isfinite(d) && d > 0.0)) return;  // check() names the fault; no combination is solved
  }
  for (std::size_t a = 0; a < k; ++a) {
    for (std::size_t b = a + 1; b < k; ++b) {
      for (std::size_t c = b + 1; c < k; ++c) {
        TipCombination combination;
        combination.trailing = {a, b, c};
        std::array<Vec3, 3> offsets{};
        for (std::size_t r = 0; r < 3; ++r) {
          const std::size_t t = combination.trailing[r];
          combination.cosines[r] = cosines(t);
          combination.lengths[r] = distance(t);
          offsets[r] = offset(t);
        }
        combination.det_a0 = det3(combination.cosines);
        combination.inverse_cosines = inverse3(combination.cosines, combination.det_a0);
        combination.inverse_offsets = inverse3(offsets, det3(offsets));
        combinations_.push_back(combination);
      }
    }
  }
}

Vec3 ProbeGeometry::offset(std::size_t k) const {
  const Vec3& tip = positions_[trailing_[k]];
  const Vec3& lead = positions_[leading_];
  return {tip[0] - lead[0], tip[1] - lead[1], tip[2] - lead[2]};
}

double ProbeGeometry::distance(std::size_t k) const {
  const Vec3 s = offset(k);
  return std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
}

Vec3 ProbeGeometry::cosines(std::size_t k) const {
  const Vec3 s = offset(k);
  const double d = distance(k);
  return {s[0] / d, s[1] / d, s[2] / d};
}

std::string ProbeGeometry::tip_name(std::size_t tip) const {
  const Vec3& p = positions_[tip];
  return fmt::format("tip {} ({:.3g}, {:.3g}, {:.3g}) mm", tip, 1e3 * p[0], 1e3 * p[1], 1e3 * p[2]);
}

Validation ProbeGeometry::check(double conditioning_min) const {
  const std::size_t n = positions_.size();
  if (n < 4) {
    return Validation::invalid(
        "tips", fmt::format("{} tip{} given: a 3-D velocity needs at least 4 tips, a leading tip and three trailing "
                            "tips not in one plane with it",
                            n, n == 1 ? "" : "s"));
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = positions_[i];
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) {
      return Validation::invalid("tips", fmt::format("tip {} has a coordinate that is not a finite number ({}, {}, {} m)",
                                                     i, p[0], p[1], p[2]));
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      if (positions_[i] == positions_[j]) {
        return Validation::invalid(
            "tips", fmt::format("tips {} and {} are at the same position ({:.3g}, {:.3g}, {:.3g}) mm: a tip is listed "
                                "twice; give each tip's own position",
                                i, j, 1e3 * positions_[i][0], 1e3 * positions_[i][1], 1e3 * positions_[i][2]));
      }
    }
  }
  if (given_leading_) {
    if (*given_leading_ >= n)
      return Validation::invalid("tips", fmt::format("the leading tip {} is not one of the {} tips (0 to {})",
                                                     *given_leading_, n, n - 1));
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      if (i != leading_ && positions_[i][0] == positions_[leading_][0]) {
        return Validation::invalid(
            "tips", fmt::format("tips {} and {} are both the most upstream (x = {:.3g} mm): the leading tip is "
                                "ambiguous; name it or move one tip downstream",
                                std::min(i, leading_), std::max(i, leading_), 1e3 * positions_[i][0]));
      }
    }
  }
  const TipCombination* best = nullptr;
  for (const auto& c : combinations_)
    if (!best || c.conditioning() > best->conditioning()) best = &c;
  const auto tips_of = [this](const TipCombination& c) {
    return fmt::format("{}, {} and {}", trailing_[c.trailing[0]], trailing_[c.trailing[1]], trailing_[c.trailing[2]]);
  };
  if (!best || best->conditioning() < kCoplanar) {
    std::string all;
    for (std::size_t i = 0; i < n; ++i) all += (all.empty() ? "" : i + 1 == n ? " and " : ", ") + std::to_string(i);
    return Validation::invalid("tips", fmt::format("tips {} lie in one plane with the leading {}: no three trailing "
                                                   "tips give a 3-D velocity; move a tip out of that plane",
                                                   all, tip_name(leading_)));
  }
  if (best->conditioning() < conditioning_min) {
    return Validation::invalid(
        "tips,conditioning-min", fmt::format("the trailing tips are nearly in one plane with the leading {}: the best combination, "
                            "tips {}, has conditioning |det A_0| = {:.3g}, below conditioning-min = {:g} (its "
                            "velocities would amplify timing errors up to {:.0f} times); move a tip out of that plane "
                            "or lower conditioning-min",
                            tip_name(leading_), tips_of(*best), best->conditioning(), conditioning_min,
                            1.5 / best->conditioning()));
  }
  return {};
}

}  // namespace awcc
