// The multi-tip solvers (awcc/multi_tip.hpp) against analytic crossings: a
// sphere of diameter D in uniform motion V pierces each tip between the two
// roots of |tip - c0 - V t| = D / 2 (computed here in long double), so Shen &
// Nakamura must give back V, D and the normals to rounding; Tian gives V for
// a plane moving along its normal. Then the fates, the combinations of a
// five-tip probe, the vector statistics against a brute-force long double
// computation, the interfacial area of every complete bubble against a
// brute-force count and of a stream of spheres against 6 c / D, the
// caution's checks at and around their limits, the grazing error and the
// options. The speed is bench/multi_tip_bench.cpp's.
#include "awcc/multi_tip.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <random>

#include "awcc/detail/awcc_steps.hpp"
#include "awcc/detail/multi_tip_steps.hpp"
#include "awcc/options.hpp"
#include "probe_builders.hpp"

namespace {

using awcc::VectorFate;
using awcc::Crossing;
using awcc::MultiTipOptions;
using awcc::PiercedBubbles;
using awcc::ProbeGeometry;
using awcc::Vec3;
using awcc::VelocityAlgorithm;
using pdp_test::cone_probe;

double norm(const Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
Vec3 minus(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double relative(const Vec3& got, const Vec3& want) { return norm(minus(got, want)) / norm(want); }

/// A sphere whose centre is at c0 at time 0 and moves at v.
struct Sphere {
  Vec3 c0;
  Vec3 v;
  double diameter;
  /// The crossing of a tip, none when the sphere misses it (long double roots).
  [[nodiscard]] std::optional<Crossing> at(const Vec3& tip) const {
    long double qv = 0, vv = 0, qq = 0;
    for (std::size_t j = 0; j < 3; ++j) {
      const long double q = static_cast<long double>(tip[j]) - c0[j];
      qv += q * v[j];
      vv += static_cast<long double>(v[j]) * v[j];
      qq += q * q;
    }
    const long double r = 0.5L * diameter;
    const long double disc = qv * qv - vv * (qq - r * r);
    if (!(disc > 0)) return std::nullopt;
    const long double root = std::sqrt(disc);
    return Crossing{static_cast<double>((qv - root) / vv), static_cast<double>((qv + root) / vv), false};
  }
  /// Centre at time t.
  [[nodiscard]] Vec3 centre(double t) const { return {c0[0] + v[0] * t, c0[1] + v[1] * t, c0[2] + v[2] * t}; }
  /// The outward unit normal where the tip touches the sphere at time t.
  [[nodiscard]] Vec3 normal(const Vec3& tip, double t) const {
    const Vec3 d = minus(tip, centre(t));
    const double n = norm(d);
    return {d[0] / n, d[1] / n, d[2] / n};
  }
};

/// The sphere's bubble as the pairing hands it over: its crossing of every tip.
PiercedBubbles pierce(const ProbeGeometry& g, const std::vector<Sphere>& spheres) {
  PiercedBubbles out(g.trailing_tips().size());
  std::vector<std::optional<Crossing>> partners(g.trailing_tips().size());
  for (const auto& s : spheres) {
    const auto lead = s.at(g.positions()[g.leading()]);
    if (!lead) continue;
    for (std::size_t k = 0; k < partners.size(); ++k) partners[k] = s.at(g.positions()[g.trailing_tips()[k]]);
    out.add(*lead, partners);
  }
  return out;
}

/// A sphere whose centre line passes at lateral offset `offset` (m, in the
/// plane normal to v) from the origin, its centre reaching that plane at t0.
Sphere sphere_through(const Vec3& v, double diameter, const Vec3& offset, double t0) {
  return {{offset[0] - v[0] * t0, offset[1] - v[1] * t0, offset[2] - v[2] * t0}, v, diameter};
}

// A vector normal to v (v not along z).
Vec3 lateral(const Vec3& v, double angle) {
  const double n = norm(v);
  const Vec3 u{v[0] / n, v[1] / n, v[2] / n};
  Vec3 a{-u[1], u[0], 0.0};
  const double na = norm(a);
  a = {a[0] / na, a[1] / na, 0.0};
  const Vec3 b{u[1] * a[2] - u[2] * a[1], u[2] * a[0] - u[0] * a[2], u[0] * a[1] - u[1] * a[0]};
  return {std::cos(angle) * a[0] + std::sin(angle) * b[0], std::cos(angle) * a[1] + std::sin(angle) * b[1],
          std::cos(angle) * a[2] + std::sin(angle) * b[2]};
}

MultiTipOptions no_statistics() {
  MultiTipOptions o;
  o.vectors_reported = 2;
  o.roc = false;
  return o;
}

TEST(MultiTip, ShenNakamuraRecoversTheVelocityDiameterAndNormalsOfASphere) {
  const Vec3 v{1.3, 0.21, -0.17};
  for (int tips : {4, 5}) {
    const ProbeGeometry g(cone_probe(tips - 1, 2e-3, 1e-3, 0.2));
    std::vector<Sphere> spheres;
    // Offsets up to 0.75 mm (R / 4) from the probe axis in several
    // directions: every tip pierced well inside (not grazing).
    for (int i = 0; i < 12; ++i) {
      const Vec3 o = lateral(v, 0.7 * i);
      const double r = 0.25e-3 * (i % 4);
      spheres.push_back(sphere_through(v, 6e-3, {r * o[0], r * o[1], r * o[2]}, 0.01 * (i + 1)));
    }
    const auto bubbles = pierce(g, spheres);
    ASSERT_EQ(bubbles.size(), spheres.size());
    const auto result = awcc::multi_tip(g, bubbles, 1.0, no_statistics());
    ASSERT_TRUE(result.ok()) << result.message;
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      const auto& b = result.bubbles[i];
      const auto& s = spheres[i];
      ASSERT_EQ(b.fate, VectorFate::solved);
      EXPECT_EQ(b.combinations, tips == 4 ? 1 : 4);
      EXPECT_LT(relative(b.velocity, v), 1e-9) << "tips " << tips << " bubble " << i;
      EXPECT_LT(norm(b.velocity_spread) / norm(v), 1e-9) << "an exact sphere: every combination agrees";
      EXPECT_NEAR(b.diameter_front, 6e-3, 6e-12);
      EXPECT_NEAR(b.diameter_rear, 6e-3, 6e-12);
      const auto lead = *s.at({0, 0, 0});
      const Vec3 nf = s.normal({0, 0, 0}, lead.front);
      const Vec3 nr = s.normal({0, 0, 0}, lead.rear);
      EXPECT_LT(norm(minus(b.normal_front, nf)), 1e-9);
      EXPECT_LT(norm(minus(b.normal_rear, nr)), 1e-9);
      // Eq. 54: the front interface's 1 / |V . n|.
      const double share = 1.0 / std::fabs(v[0] * nf[0] + v[1] * nf[1] + v[2] * nf[2]);
      EXPECT_NEAR(b.area_share, share, 1e-9 * share);
      // The interaction time span: the leading front to the last rear.
      double last = lead.rear;
      for (std::size_t k = 0; k < g.trailing_tips().size(); ++k) last = std::max(last, bubbles.partner(i, k)->rear);
      EXPECT_DOUBLE_EQ(b.weight, last - lead.front);
    }
  }
}

// Eqs. 30-54 as METHOD 11.4 writes them (determinants with replaced
// columns), in long double, for times that are not a sphere's: the solver's
// inverse-matrix form must be the same algebra.
TEST(MultiTip, TheSolverIsMethodsDeterminantFormulas) {
  const ProbeGeometry g(cone_probe(3, 2e-3, 1.2e-3, 0.4));
  const auto& c = g.combinations()[0];
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(-2e-4, 2e-4);
  using M = std::array<std::array<long double, 3>, 3>;
  const auto det = [](const M& m) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  for (int trial = 0; trial < 50; ++trial) {
    const Crossing lead{0.5, 0.5 + 3e-3 + jitter(rng), false};
    std::array<Crossing, 3> at{};
    for (auto& x : at) x = {lead.front + 1.6e-3 + jitter(rng), lead.rear + 1.6e-3 + jitter(rng), false};
    awcc::detail::CombinationSolution s;
    ASSERT_TRUE(awcc::detail::solve_combination(c, lead, {&at[0], &at[1], &at[2]}, VelocityAlgorithm::shen_nakamura, s));
    M a0{};
    std::array<long double, 3> inv_vm{}, ef{}, er{};
    for (std::size_t k = 0; k < 3; ++k) {
      for (std::size_t j = 0; j < 3; ++j) a0[k][j] = c.cosines[k][j];
      const long double df = static_cast<long double>(at[k].front) - lead.front;
      const long double dr = static_cast<long double>(at[k].rear) - lead.rear;
      inv_vm[k] = (df + dr) / (2.0L * c.lengths[k]);  // Eq. 30
    }
    const auto replaced = [&](std::size_t j, const std::array<long double, 3>& col) {
      M m = a0;
      for (std::size_t k = 0; k < 3; ++k) m[k][j] = col[k];
      return det(m);
    };
    const long double d0 = det(a0);
    long double sum_a = 0;
    std::array<long double, 3> a0j{};
    for (std::size_t j = 0; j < 3; ++j) sum_a += (a0j[j] = replaced(j, inv_vm)) * a0j[j];
    const long double speed = std::fabs(d0) / std::sqrt(sum_a);  // Eq. 37
    for (std::size_t j = 0; j < 3; ++j)
      EXPECT_NEAR(s.velocity[j], static_cast<double>(speed * speed * a0j[j] / d0), 1e-11 * static_cast<double>(speed));
    const long double t0 = static_cast<long double>(lead.rear) - lead.front;
    for (std::size_t k = 0; k < 3; ++k) {
      const long double df = static_cast<long double>(at[k].front) - lead.front;
      const long double dr = static_cast<long double>(at[k].rear) - lead.rear;
      ef[k] = speed * speed * df * (dr + t0) / c.lengths[k] - c.lengths[k];  // Eq. 43
      er[k] = speed * speed * dr * (df - t0) / c.lengths[k] - c.lengths[k];  // Eq. 44
    }
    long double sbf = 0, sbr = 0, sab = 0;
    std::array<long double, 3> bf{};
    for (std::size_t j = 0; j < 3; ++j) {
      bf[j] = replaced(j, ef);
      const long double br = replaced(j, er);
      sbf += bf[j] * bf[j];
      sbr += br * br;
      sab += a0j[j] * bf[j];
    }
    const double df_ = static_cast<double>(std::sqrt(sbf) / std::fabs(d0));  // Eq. 50
    EXPECT_NEAR(s.diameter_front, df_, 1e-10 * df_);
    EXPECT_NEAR(s.diameter_rear, static_cast<double>(std::sqrt(sbr) / std::fabs(d0)), 1e-10 * df_);
    for (std::size_t j = 0; j < 3; ++j)  // Eq. 51
      EXPECT_NEAR(s.normal_front[j], static_cast<double>((d0 > 0 ? 1 : -1) * bf[j] / std::sqrt(sbf)), 1e-10);
    const double iac = static_cast<double>(sum_a * std::sqrt(sbf) / std::fabs(d0 * sab));  // Eq. 54
    EXPECT_NEAR(s.area_share, iac, 1e-10 * iac);
  }
}

TEST(MultiTip, TianRecoversThePlaneInterfaceVelocityAlongItsNormal) {
  // A slab of air between two planes of normal n moving at speed u along n:
  // it reaches point p at t0 + p . n / u (front) and L / u later (rear).
  const ProbeGeometry g({{0, 0, 0}, {5e-3, 0, 0}, {5e-3, 1.5e-3, 0}, {5e-3, 0, 1.5e-3}});
  const Vec3 n{0.96, 0.2, std::sqrt(1.0 - 0.96 * 0.96 - 0.04)};
  const double u = 2.4, thickness = 3e-3;
  PiercedBubbles bubbles(3);
  for (int h = 0; h < 5; ++h) {
    const double t0 = 0.1 * (h + 1);
    const auto at = [&](const Vec3& p) {
      const double t = t0 + (p[0] * n[0] + p[1] * n[1] + p[2] * n[2]) / u;
      return Crossing{t, t + thickness / u, false};
    };
    std::vector<std::optional<Crossing>> partners;
    for (std::size_t k : g.trailing_tips()) partners.push_back(at(g.positions()[k]));
    bubbles.add(at(g.positions()[0]), partners);
  }
  for (auto algorithm : awcc::velocity_algorithms) {
    auto o = no_statistics();
    o.algorithm = algorithm;
    const auto r = awcc::multi_tip(g, bubbles, 1.0, o);
    ASSERT_TRUE(r.ok()) << r.message;
    for (const auto& b : r.bubbles) EXPECT_LT(relative(b.velocity, {u * n[0], u * n[1], u * n[2]}), 1e-9);
    EXPECT_EQ(r.interfacial_area_paired.has_value(), algorithm == VelocityAlgorithm::shen_nakamura);
    // The estimator from the speeds alone: both algorithms, 4 N_0 / (u T).
    ASSERT_TRUE(r.interfacial_area.has_value());
    EXPECT_NEAR(*r.interfacial_area, 4.0 * 5.0 / (u * 1.0), 1e-9 * *r.interfacial_area);
    if (algorithm == VelocityAlgorithm::tian) {
      EXPECT_TRUE(std::isnan(r.bubbles[0].diameter_front));
    }
  }
}

TEST(MultiTip, FatesOfBubblesWithoutAVectorAreCountedNeverAHugeNumber) {
  const ProbeGeometry g(cone_probe(3, 2e-3, 1e-3));
  const Crossing lead{0.2, 0.203, false};
  const Crossing later{0.2016, 0.2046, false};
  PiercedBubbles bubbles(3);
  bubbles.add(lead, std::vector<std::optional<Crossing>>{later, later, later});  // solved (a plane along x)
  bubbles.add(lead, std::vector<std::optional<Crossing>>{later, std::nullopt, later});  // two paired tips
  bubbles.add({0.0, 0.001, true}, std::vector<std::optional<Crossing>>{later, later, later});  // cut at the start
  bubbles.add(lead, std::vector<std::optional<Crossing>>{later, Crossing{0.2016, 0.2046, true}, later});  // cut partner
  bubbles.add(lead, std::vector<std::optional<Crossing>>{lead, lead, lead});  // zero lags
  const Crossing nan{std::nan(""), 0.2046, false};
  bubbles.add(lead, std::vector<std::optional<Crossing>>{nan, later, later});  // not a number
  // Lags of one ulp of the times: within their rounding, no direction.
  const Crossing ulp{std::nextafter(0.2, 1.0), std::nextafter(0.203, 1.0), false};
  bubbles.add(lead, std::vector<std::optional<Crossing>>{ulp, lead, lead});
  const auto r = awcc::multi_tip(g, bubbles, 1.0, no_statistics());
  const std::vector<VectorFate> want{VectorFate::solved,     VectorFate::too_few_tips, VectorFate::censored,
                                     VectorFate::too_few_tips, VectorFate::degenerate, VectorFate::degenerate,
                                     VectorFate::degenerate};
  ASSERT_EQ(r.bubbles.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(r.bubbles[i].fate, want[i]) << i;
    if (want[i] != VectorFate::solved) {
      EXPECT_TRUE(std::isnan(r.bubbles[i].velocity[0])) << i;
    }
  }
  EXPECT_LT(relative(r.bubbles[0].velocity, {2e-3 / 1.6e-3, 0, 0}), 1e-9);
  EXPECT_EQ(r.partners_censored, 1);
  EXPECT_EQ(r.combinations_degenerate, 3);
  EXPECT_EQ(r.count(VectorFate::too_few_tips), 2);
  EXPECT_EQ(r.bubbles_complete, 6) << "every leading bubble but the censored one";
  EXPECT_FALSE(r.ok()) << "one vector is too few for statistics";
  EXPECT_NE(r.message.find("1 of 7 leading bubbles have an accepted velocity vector (1 solved, 1 censored, 2 "
                           "too_few_tips, 3 degenerate)"),
            std::string::npos)
      << r.message;
  EXPECT_NE(r.report().find("no statistics"), std::string::npos);
}

TEST(MultiTip, FiveTipsAverageTheCombinationsAndKeepTheirSpread) {
  const ProbeGeometry g(cone_probe(4, 2e-3, 1e-3, 0.1));
  const Sphere s = sphere_through({1.1, 0.1, 0.05}, 5e-3, {0.0, 0.2e-3, -0.1e-3}, 0.05);
  const auto exact = pierce(g, {s});
  // Delay trailing tip 2's interfaces by 40 us: the combinations that use it
  // disagree with those that do not, by amounts computed here per combination.
  PiercedBubbles bubbles = exact;
  bubbles.trailing[2]->front += 40e-6;
  bubbles.trailing[2]->rear += 40e-6;
  const auto r = awcc::multi_tip(g, bubbles, 1.0, no_statistics());
  ASSERT_EQ(r.bubbles[0].fate, VectorFate::solved);
  ASSERT_EQ(r.bubbles[0].combinations, 4);
  std::array<Vec3, 4> each{};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& c = g.combinations()[i];
    std::array<const Crossing*, 3> at{};
    for (std::size_t k = 0; k < 3; ++k) at[k] = &*bubbles.partner(0, c.trailing[k]);
    awcc::detail::CombinationSolution one;
    ASSERT_TRUE(awcc::detail::solve_combination(c, bubbles.leading[0], at, VelocityAlgorithm::shen_nakamura, one));
    each[i] = one.velocity;
  }
  for (std::size_t j = 0; j < 3; ++j) {
    long double m = 0, q = 0;
    for (const auto& e : each) m += e[j];
    m /= 4;
    for (const auto& e : each) q += (e[j] - m) * (e[j] - m);
    EXPECT_NEAR(r.bubbles[0].velocity[j], static_cast<double>(m), 1e-12);
    EXPECT_NEAR(r.bubbles[0].velocity_spread[j], static_cast<double>(std::sqrt(q / 4)), 1e-12);
  }
  EXPECT_GT(norm(r.bubbles[0].velocity_spread), 1e-3) << "the delay must show as spread";
  // The one combination without trailing tip 2, {0, 1, 3}, is exact.
  EXPECT_LT(relative(each[1], s.v), 1e-9);
}

TEST(MultiTip, IllConditionedCombinationsAreSkippedAndCountedAtAndAroundTheLimit) {
  // Five tips: trailing tips 1-3 on a cone whose conditioning is the limit
  // times `factor`; tip 4, off to the side, makes the other three
  // combinations well conditioned (0.108, 0.108 and 0.232).
  const Vec3 v{1.0, 0.05, 0.02};
  for (double factor : {0.999, 1.0, 1.001}) {
    MultiTipOptions o = no_statistics();
    const double a = pdp_test::cone_angle_for(factor * o.conditioning_min);
    auto tips = cone_probe(3, 2e-3 * std::cos(a), 2e-3 * std::sin(a));
    tips.push_back({0.5e-3, 1.5e-3, 0.0});
    const ProbeGeometry g(tips);
    const double det = g.combinations()[0].conditioning();
    if (factor == 1.0) o.conditioning_min = det;  // exactly at the limit
    const auto r = awcc::multi_tip(g, pierce(g, {sphere_through(v, 8e-3, {0, 0, 0}, 0.1)}), 1.0, o);
    ASSERT_EQ(r.bubbles[0].fate, VectorFate::solved);
    const bool skipped = factor < 1.0;
    EXPECT_EQ(r.combinations_ill_conditioned, skipped ? 1 : 0) << factor;
    EXPECT_EQ(r.bubbles[0].combinations_skipped, skipped ? 1 : 0);
    EXPECT_EQ(r.bubbles[0].combinations, skipped ? 3 : 4);
    EXPECT_LT(relative(r.bubbles[0].velocity, v), 1e-9);
  }
  // A bubble paired only at the ill-conditioned three: no vector, its fate says why.
  MultiTipOptions o = no_statistics();
  const double a = pdp_test::cone_angle_for(0.5 * o.conditioning_min);
  auto tips = cone_probe(3, 2e-3 * std::cos(a), 2e-3 * std::sin(a));
  tips.push_back({0.5e-3, 1.5e-3, 0.0});
  const ProbeGeometry g(tips);
  auto bubbles = pierce(g, {sphere_through(v, 8e-3, {0, 0, 0}, 0.1)});
  bubbles.trailing[3].reset();
  const auto r = awcc::multi_tip(g, bubbles, 1.0, o);
  EXPECT_EQ(r.bubbles[0].fate, VectorFate::ill_conditioned);
  EXPECT_TRUE(std::isnan(r.bubbles[0].velocity[0]));
}

TEST(MultiTip, StatisticsAreTheWeightedMomentsOfABruteForceComputation) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> span(1e-3, 9e-3);
  awcc::MultiTipResult r;
  r.record_length = 30.0;
  const int n = 5000;
  for (int i = 0; i < n; ++i) {
    awcc::BubbleVector b;
    b.fate = i % 7 == 3 ? VectorFate::too_few_tips : VectorFate::solved;
    b.weight = span(rng);
    b.velocity = {3.0 + 0.4 * n01(rng), -0.2 + 0.3 * n01(rng), 0.1 + 0.2 * n01(rng)};
    b.velocity[1] += 0.5 * (b.velocity[0] - 3.0);  // correlated: a non-zero off-diagonal stress
    b.diameter_front = 4e-3 + 1e-4 * n01(rng);
    b.diameter_rear = 4e-3 + 1e-4 * n01(rng);
    b.area_share = 1.0 / (2.0 + n01(rng) * 0.1);
    r.bubbles.push_back(b);
  }
  MultiTipOptions o;
  o.roc = false;
  awcc::detail::multi_tip_summarise(r, o);
  ASSERT_TRUE(r.ok()) << r.message;
  long double w = 0, shares = 0, dsum = 0;
  std::array<long double, 3> m{};
  std::array<std::array<long double, 3>, 3> rs{};
  long double accepted = 0;
  for (const auto& b : r.bubbles) {
    if (b.fate != VectorFate::solved) continue;
    ++accepted;
    w += b.weight;
    shares += b.area_share;
    dsum += b.diameter_front;
    for (std::size_t j = 0; j < 3; ++j) m[j] += static_cast<long double>(b.weight) * b.velocity[j];
  }
  for (auto& x : m) x /= w;
  for (const auto& b : r.bubbles) {
    if (b.fate != VectorFate::solved) continue;
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t k = 0; k < 3; ++k) rs[j][k] += b.weight * (b.velocity[j] - m[j]) * (b.velocity[k] - m[k]);
  }
  EXPECT_EQ(r.bubbles_accepted, static_cast<std::int64_t>(accepted));
  const long double speed = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  EXPECT_NEAR(r.speed, static_cast<double>(speed), 1e-13 * r.speed);
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_NEAR(r.velocity[j], static_cast<double>(m[j]), 1e-13 * r.speed);
    for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(r.reynolds_stress[j][k], static_cast<double>(rs[j][k] / w), 1e-13);
    const double tu = static_cast<double>(std::sqrt(rs[j][j] / w) / speed);
    EXPECT_NEAR(r.turbulence_intensity[j], tu, 1e-12 * tu);
    // METHOD 4 item 8.
    const double nn = static_cast<double>(accepted);
    const double rms = static_cast<double>(std::sqrt(rs[j][j] / w));
    EXPECT_NEAR(r.velocity_ci95[j].upper - r.velocity[j], 1.96 * rms / std::sqrt(nn), 1e-12);
    EXPECT_NEAR(r.velocity_rms_ci95[j].lower, rms - 1.96 * rms / std::sqrt(2 * nn), 1e-12);
    EXPECT_NEAR(r.turbulence_intensity_ci95[j].upper - tu, 1.96 * std::sqrt(tu * tu * (tu * tu / nn + 0.5 / nn)),
                1e-12);
  }
  EXPECT_GT(std::fabs(r.reynolds_stress[0][1]), 0.05) << "the correlated components must show";
  EXPECT_NEAR(*r.interfacial_area_paired, static_cast<double>(2 * shares / 30.0), 1e-12 * *r.interfacial_area_paired);
  // Every bubble here is complete (none censored): N_0 counts the
  // too_few_tips ones too; m is the plain mean of 1 / |v| of the accepted.
  long double inv = 0, inv2 = 0;
  for (const auto& b : r.bubbles) {
    if (b.fate != VectorFate::solved) continue;
    const long double u = 1.0L / std::sqrt(static_cast<long double>(b.velocity[0]) * b.velocity[0] +
                                           static_cast<long double>(b.velocity[1]) * b.velocity[1] +
                                           static_cast<long double>(b.velocity[2]) * b.velocity[2]);
    inv += u;
    inv2 += u * u;
  }
  const long double mean_inv = inv / accepted;
  const long double var_inv = (inv2 - accepted * mean_inv * mean_inv) / (accepted - 1);
  EXPECT_EQ(r.bubbles_complete, n);
  const double a = static_cast<double>(4.0L * n * mean_inv / 30.0L);
  EXPECT_NEAR(*r.interfacial_area, a, 1e-12 * a);
  const double half = 1.96 * a * static_cast<double>(std::sqrt(1.0L / n + var_inv / (accepted * mean_inv * mean_inv)));
  EXPECT_NEAR(r.interfacial_area_ci95->upper - a, half, 1e-9 * half);
  EXPECT_NEAR(a - r.interfacial_area_ci95->lower, half, 1e-9 * half);
  EXPECT_TRUE(r.caution.empty()) << r.caution;
  EXPECT_NEAR(*r.diameter_front, static_cast<double>(dsum / accepted), 1e-15);
}

TEST(MultiTip, TheOutlierCutoffRejectsABubbleOnAnyComponent) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01;
  awcc::MultiTipResult r;
  r.record_length = 10.0;
  for (int i = 0; i < 400; ++i) {
    awcc::BubbleVector b;
    b.fate = VectorFate::solved;
    b.weight = 1e-3;
    b.velocity = {2.0 + 0.1 * n01(rng), 0.1 * n01(rng), 0.1 * n01(rng)};
    r.bubbles.push_back(b);
  }
  r.bubbles[17].velocity[2] = 3.0;  // normal in x and y, wild in z (a mis-paired tip)
  awcc::detail::multi_tip_summarise(r, MultiTipOptions{});
  EXPECT_EQ(r.bubbles[17].fate, VectorFate::roc);
  // The same cutoff as AWCC's, on z alone, rejects it too.
  std::vector<double> z;
  std::vector<bool> keep(400, true);
  for (const auto& b : r.bubbles) z.push_back(b.velocity[2]);
  awcc::detail::robust_outlier_cutoff(z, keep);
  EXPECT_FALSE(keep[17]);
  EXPECT_LT(std::fabs(r.velocity[2]), 0.03) << "the outlier must not reach the mean";
}

// Slabs of air moving along their normals (the planes of Tian's test) at
// known speeds u_h, with bubbles that miss a trailing tip, are cut by the
// record's start or have no direction (zero lags): the estimator counts every
// complete one (N_0) at the accepted slabs' mean 1 / u_h, exactly.
TEST(MultiTip, TheInterfacialAreaCountsEveryCompleteBubbleAtTheAcceptedMeanOfOneOverSpeed) {
  const ProbeGeometry g({{0, 0, 0}, {5e-3, 0, 0}, {5e-3, 1.5e-3, 0}, {5e-3, 0, 1.5e-3}});
  PiercedBubbles bubbles(3);
  long double inv = 0, inv2 = 0;
  const int solved = 40;
  for (int h = 0; h < solved; ++h) {
    const double u = 1.5 + 0.05 * h, t0 = 0.1 * (h + 1);
    const double ny = 0.02 * (h % 5) - 0.04, nz = 0.03 * (h % 3) - 0.03;
    const Vec3 n{std::sqrt(1.0 - ny * ny - nz * nz), ny, nz};
    const auto at = [&](const Vec3& p) {
      const double t = t0 + (p[0] * n[0] + p[1] * n[1] + p[2] * n[2]) / u;
      return Crossing{t, t + 2e-3 / u, false};
    };
    std::vector<std::optional<Crossing>> partners;
    for (std::size_t k : g.trailing_tips()) partners.push_back(at(g.positions()[k]));
    bubbles.add(at(g.positions()[0]), partners);
    inv += 1.0L / u;
    inv2 += 1.0L / (static_cast<long double>(u) * u);
    if (h % 6 == 0) {  // the same slab with a partner missing: no vector, still a bubble
      partners[h % 3].reset();
      bubbles.add(at(g.positions()[0]), partners);
    }
  }
  const Crossing lead{5.0, 5.002, false};
  bubbles.add({0.0, 0.001, true}, std::vector<std::optional<Crossing>>{lead, lead, lead});  // cut at the start
  bubbles.add({12.4, 12.5, true}, std::vector<std::optional<Crossing>>{std::nullopt, lead, lead});  // cut at the end
  for (int i = 0; i < 3; ++i) bubbles.add(lead, std::vector<std::optional<Crossing>>{lead, lead, lead});  // zero lags
  const double t = 12.5;
  const long double n0 = solved + 7 + 3;  // solved, missing a partner, degenerate; not the 2 censored
  const long double m = inv / solved;
  const double want = static_cast<double>(4.0L * n0 * m / t);
  const long double var = (inv2 - solved * m * m) / (solved - 1);
  const double half = 1.96 * want * static_cast<double>(std::sqrt(1.0L / n0 + var / (solved * m * m)));
  for (auto algorithm : awcc::velocity_algorithms) {
    auto o = no_statistics();
    o.algorithm = algorithm;
    const auto r = awcc::multi_tip(g, bubbles, t, o);
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_EQ(r.bubbles_accepted, solved);
    EXPECT_EQ(r.bubbles_complete, static_cast<std::int64_t>(n0));
    EXPECT_EQ(r.count(VectorFate::censored), 2);
    ASSERT_TRUE(r.interfacial_area && r.interfacial_area_ci95);
    EXPECT_NEAR(*r.interfacial_area, want, 1e-9 * want) << to_string(algorithm);
    EXPECT_NEAR(r.interfacial_area_ci95->upper - want, half, 1e-6 * half);
    EXPECT_NEAR(want - r.interfacial_area_ci95->lower, half, 1e-6 * half);
    EXPECT_EQ(r.interfacial_area_paired.has_value(), algorithm == VelocityAlgorithm::shen_nakamura);
    EXPECT_NE(r.report().find("N_0 = 50 complete leading bubbles"), std::string::npos) << r.report();
  }
}

// The caution's checks at and around their limits (multi_tip.hpp), on
// vectors handed to the statistics directly.
TEST(MultiTip, CautionFlagsATailOfSlowVectorsAndACutoffThatRejectsMostAtTheirLimits) {
  const auto summarised = [](double slow_speed, int accepted, int rejected) {
    awcc::MultiTipResult r;
    r.record_length = 10.0;
    for (int i = 0; i < accepted + rejected; ++i) {
      awcc::BubbleVector b;
      b.fate = i < accepted ? VectorFate::solved : VectorFate::roc;
      b.weight = 1e-3;
      b.velocity = {i == 0 ? slow_speed : 1.0, 0.0, 0.0};
      r.bubbles.push_back(b);
    }
    awcc::detail::multi_tip_summarise(r, MultiTipOptions{.roc = false});
    return r;
  };
  // Eleven vectors, ten at 1 m/s (the median) and one at s: m x median =
  // (10 + 1 / s) / 11, above 1.25 for s < 0.2667.
  EXPECT_TRUE(summarised(0.3, 11, 0).caution.empty()) << "(10 + 3.33) / 11 = 1.21";
  const auto slow = summarised(0.25, 11, 0);
  ASSERT_TRUE(slow.ok()) << slow.message;
  EXPECT_NE(slow.caution.find("1.27 times 1/(median speed)"), std::string::npos) << slow.caution;
  EXPECT_NE(slow.report().find("caution: "), std::string::npos);
  // Rejected by the cutoff: exactly half is not more than half.
  EXPECT_TRUE(summarised(1.0, 30, 30).caution.empty());
  const auto cut = summarised(1.0, 30, 31);
  EXPECT_NE(cut.caution.find("rejected 31 of 61 solved vectors"), std::string::npos) << cut.caution;
  EXPECT_EQ(cut.caution.find("median"), std::string::npos) << "one reason only: " << cut.caution;
}

// A stream of equal spheres through a probe of nanometre spacing: each
// sphere's line passes at an offset uniform over the disk of radius R around
// the leading tip (the tip meets bubbles in proportion to the area), so it
// pierces the leading tip at angle theta, sin theta = s = offset / R, with s^2
// uniform on [0, 1]. Its chord time at tip 0 is D cos theta / |V| and its
// front interface's 1 / |V . n| is 1 / (|V| cos theta). Over N bubbles in T:
//   c = sum D cos theta / (|V| T),  a = (2 / T) sum 1 / (|V| cos theta),
//   a / (6 c / D) = mean(1 / cos theta) / (3 mean(cos theta)),
// with E[1 / cos] = 2 and E[cos] = 2/3: ratio 1 in expectation.
// Deviations: (1) bubbles whose line passes within about e = 3 nm of the rim
// miss a trailing tip (no vector): the lost share of E[1 / cos] is
// 2 sqrt(1 - (1 - eps)^2) ~ 2 sqrt(2 eps), eps = e / R = 1.2e-6, i.e. 0.15 %
// of 2. (2) sampling: with the rim cut, E[1 / cos^2] = -ln(1 - s_max^2) =
// ln(1 / (2 eps)) = 13.1, so sd(1 / cos) = sqrt(13.1 - 4) = 3.0, and sd(cos) =
// sqrt(1/2 - 4/9) = 0.24; at N = 200,000 the relative sd of the means are
// 3.0 / 2 / 447 = 0.34 % and 0.24 / (2/3) / 447 = 0.08 %, 0.35 % together.
// Bound: 0.15 % + 5 x 0.35 % = 1.9 %, asserted as 2 % for the paired sum.
// The estimator of every bubble, a = 4 N / (|V| T) here (one speed), gives
// a / (6 c / D) = (2/3) / mean(cos theta): no rim loss (every bubble counts)
// and only the 0.08 % sd of mean(cos theta); 5 sd = 0.4 %, asserted as 0.5 %.
TEST(MultiTip, InterfacialAreaOfAStreamOfEqualSpheresIsSixCOverD) {
  const ProbeGeometry g(cone_probe(3, 4e-9, 2e-9, 0.5));
  const Vec3 v{1.4, 0.1, -0.06};
  const double d = 5e-3, r = 0.5 * d, speed = norm(v);
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const int n = 200000;
  const double gap = 0.02;  // s between arrivals: the record length is n gaps
  PiercedBubbles bubbles(3);
  bubbles.reserve(n);
  double chords = 0.0;
  std::vector<std::optional<Crossing>> partners(3);
  for (int i = 0; i < n; ++i) {
    const double s = std::sqrt(u01(rng)), phi = 2.0 * std::numbers::pi * u01(rng);
    const Vec3 o = lateral(v, phi);
    // Each bubble's times relative to its own arrival (10 ms): differences of
    // nanosecond lags stay exact in doubles; the stream's T is n gaps.
    const Sphere sphere = sphere_through(v, d, {s * r * o[0], s * r * o[1], s * r * o[2]}, 0.01);
    const auto lead = sphere.at({0, 0, 0});
    if (!lead) continue;  // s = 1 exactly: a tangent line
    chords += lead->chord_time();
    for (std::size_t k = 0; k < 3; ++k) partners[k] = sphere.at(g.positions()[k + 1]);
    bubbles.add(*lead, partners);
  }
  const double t = n * gap;
  const double c = chords / t;
  const auto result = awcc::multi_tip(g, bubbles, t, MultiTipOptions{.roc = false});
  ASSERT_TRUE(result.ok()) << result.message;
  const double ratio = *result.interfacial_area_paired / (6.0 * c / d);
  const double ratio_all = *result.interfacial_area / (6.0 * c / d);
  std::printf("stream of %d spheres: c = %.5f, a_p = %.4f 1/m, a = %.4f 1/m, 6c/D = %.4f 1/m, ratios %.5f and %.5f; "
              "%lld without a vector\n",
              n, c, *result.interfacial_area_paired, *result.interfacial_area, 6.0 * c / d, ratio, ratio_all,
              static_cast<long long>(result.bubbles_total - result.bubbles_accepted));
  EXPECT_NEAR(ratio, 1.0, 0.02);
  EXPECT_NEAR(ratio_all, 1.0, 0.005);
  EXPECT_EQ(result.bubbles_complete, result.bubbles_total);
  EXPECT_NEAR(*result.diameter_front, d, 1e-6 * d);
  EXPECT_LT(relative(result.velocity, v), 1e-6);
  (void)speed;
}

// Grazing: the interface times a sampled signal gives (edges half way between
// samples, fs = 200 kHz) instead of the exact ones, for lines ever closer to
// the rim of the sphere at the leading tip (sin theta = offset / R; the chord
// there shrinks as cos theta). The velocity uses centre lags, whose errors
// are at most 1 / fs each (two edges, 1 / (2 fs) each), so
// |dw| <= ||A_0^-1|| |db| <= (1.5 / det A_0) sqrt(3) / (fs min |S_0k|) |w|:
// a bound on the relative speed error at any offset, grazing or not. The
// sizes come from the E's, whose absolute errors are about |V| / fs whatever
// the offset: D and n keep their absolute accuracy, but the IAC share
// 1 / (|V| cos theta) takes a relative error of about tan theta dtheta,
// which grows without bound as the sphere grazes. Measured and bounded here.
TEST(MultiTip, GrazingBubblesErrorMeasuredAndBounded) {
  const double fs = 200e3;
  // A probe small against the bubble, so that the line can pass near the
  // rim at the leading tip and still pierce every trailing tip.
  const ProbeGeometry g(cone_probe(3, 0.5e-3, 0.25e-3, 0.0));
  const double det = g.combinations()[0].conditioning();
  const Vec3 v{1.0, 0.03, 0.02};
  const double d = 20e-3, r = 0.5 * d;
  const double speed_bound = 1.5 / det * std::sqrt(3.0) * norm(v) / (fs * g.distance(0));
  const auto sampled = [fs](const Crossing& x) {
    return Crossing{(std::ceil(x.front * fs) - 0.5) / fs, (std::ceil(x.rear * fs) - 0.5) / fs, false};
  };
  std::printf("grazing (fs = 200 kHz, D = 20 mm, |V| = 1 m/s, probe dx = 0.5 mm, r = 0.25 mm, det A_0 = %.3f): speed "
              "error bound %.2f %%\n",
              det, 100.0 * speed_bound);
  std::printf("  sin theta  cos theta  speed err %%  D err %%  normal err deg  IAC share err %%  (max over 64 phases)\n");
  const std::vector<double> offsets{0.0, 0.5, 0.8, 0.9, 0.95, 0.98, 0.985};
  std::vector<double> d_errors, share_errors;
  for (double f : offsets) {
    double worst_speed = 0, worst_d = 0, worst_n = 0, worst_share = 0;
    for (int i = 0; i < 64; ++i) {
      // Towards trailing tip 1, the side where all three stay inside the sphere.
      const Vec3 o = lateral(v, 0.0);
      const Sphere sphere = sphere_through(v, d, {f * r * o[0], f * r * o[1], f * r * o[2]}, 0.01 + i * 0.0781e-6);
      PiercedBubbles bubbles(3);
      const auto lead = sphere.at({0, 0, 0});
      std::vector<std::optional<Crossing>> at;
      bool all = lead.has_value();
      for (std::size_t k = 1; k < 4; ++k) {
        at.push_back(sphere.at(g.positions()[k]));
        all = all && at.back();
        if (at.back()) at.back() = sampled(*at.back());
      }
      ASSERT_TRUE(all) << "offset " << f << " must pierce every tip";
      bubbles.add(sampled(*lead), at);
      const auto res = awcc::multi_tip(g, bubbles, 1.0, MultiTipOptions{.roc = false, .vectors_reported = 2});
      const auto& b = res.bubbles[0];
      ASSERT_EQ(b.fate, VectorFate::solved);
      worst_speed = std::max(worst_speed, std::fabs(norm(b.velocity) - norm(v)) / norm(v));
      worst_d = std::max(worst_d, std::fabs(b.diameter_front - d) / d);
      const Vec3 nf = sphere.normal({0, 0, 0}, lead->front);
      const double cosang =
          std::clamp(b.normal_front[0] * nf[0] + b.normal_front[1] * nf[1] + b.normal_front[2] * nf[2], -1.0, 1.0);
      worst_n = std::max(worst_n, std::acos(cosang) * 180.0 / std::numbers::pi);
      const double share = 1.0 / std::fabs(v[0] * nf[0] + v[1] * nf[1] + v[2] * nf[2]);
      worst_share = std::max(worst_share, std::fabs(b.area_share - share) / share);
    }
    std::printf("  %9.3f  %9.3f  %11.3f  %7.3f  %14.3f  %15.2f\n", f, std::sqrt(1 - f * f), 100 * worst_speed,
                100 * worst_d, worst_n, 100 * worst_share);
    EXPECT_LE(worst_speed, speed_bound) << "offset " << f;
    d_errors.push_back(worst_d);
    share_errors.push_back(worst_share);
  }
  // Measured (the printed table); bounds with a margin over it: the diameter
  // stays within 2 % at every offset; the IAC share within 1 % at sin theta
  // <= 0.8 and within 15 % at 0.985, where it is many times the central error.
  for (double e : d_errors) EXPECT_LT(e, 0.02);
  for (std::size_t i = 0; i <= 2; ++i) EXPECT_LT(share_errors[i], 0.01) << offsets[i];
  EXPECT_LT(share_errors.back(), 0.15);
  EXPECT_GT(share_errors.back(), 4.0 * share_errors.front()) << "grazing must cost accuracy";
}

TEST(MultiTip, OptionsAreDeclaredOnceAndValidated) {
  MultiTipOptions o;
  std::vector<bool> used(2, false);
  const std::vector<awcc::OptionSetting> settings{{"velocity-algorithm", "tian", ""}, {"conditioning-min", "0.2", ""}};
  awcc::apply_settings(awcc::multi_tip_option_fields(), std::span<const awcc::OptionSetting>(settings), o, used);
  EXPECT_EQ(o.algorithm, VelocityAlgorithm::tian);
  EXPECT_DOUBLE_EQ(o.conditioning_min, 0.2);
  EXPECT_TRUE(used[0] && used[1]);
  for (const auto& f : awcc::multi_tip_option_fields()) {
    EXPECT_FALSE(f.help.empty()) << f.name;
    MultiTipOptions again;
    f.parse(again, f.format(o));  // what format writes, parse reads
    EXPECT_EQ(f.format(again), f.format(o)) << f.name;
  }
  EXPECT_EQ(awcc::multi_tip_option_fields()[0].format(MultiTipOptions{}), "shen-nakamura");
  try {
    std::vector<bool> u(1);
    const std::vector<awcc::OptionSetting> bad{{"velocity-algorithm", "kim", ""}};
    awcc::apply_settings(awcc::multi_tip_option_fields(), std::span<const awcc::OptionSetting>(bad), o, u);
    ADD_FAILURE() << "accepted";
  } catch (const awcc::OptionError& e) {
    EXPECT_STREQ(e.what(), "velocity-algorithm: 'kim' is not one of shen-nakamura | tian");
  }
  o.conditioning_min = 0.0;
  EXPECT_EQ(o.validate().quantity, "conditioning-min");
  o.conditioning_min = 1.5;
  EXPECT_EQ(o.validate().quantity, "conditioning-min");
  EXPECT_EQ(MultiTipOptions{.vectors_reported = 1}.validate().quantity, "vectors-reported");
  // The solvers refuse a geometry naming its tip, and bubbles of another probe.
  const ProbeGeometry flat({{0, 0, 0}, {2e-3, 1e-3, 0}, {2e-3, -1e-3, 0}, {3e-3, 0, 0}});
  EXPECT_THROW((void)awcc::multi_tip(flat, PiercedBubbles(3), 1.0), awcc::OptionError);
  EXPECT_THROW((void)awcc::multi_tip(ProbeGeometry(cone_probe(3, 2e-3, 1e-3)), PiercedBubbles(4), 1.0),
               std::invalid_argument);
  EXPECT_THROW((void)awcc::multi_tip(ProbeGeometry(cone_probe(3, 2e-3, 1e-3)), PiercedBubbles(3), 0.0),
               std::invalid_argument);
}

}  // namespace

// The joint pairing (pair_probe) on constructed crossings whose answer is
// known: a sphere's exact crossings of pdp's four-tip sample geometry, with
// V_ref = 5 m/s, at and around each decision limit (window, speed band,
// cone, one candidate, one bubble, diameters, claims).
namespace pairing {

using awcc::BubbleFate;
using awcc::EventOptions;

const std::vector<Vec3> kSample{{0, 0, 0}, {5e-3, 0, 0}, {5e-3, 1.5e-3, 0}, {5e-3, 0, 1.5e-3}};
constexpr double kRef = 5.0;

// Every tip's crossings of the spheres (a missed tip has none), plus extras.
std::vector<std::vector<Crossing>> crossings_of(const ProbeGeometry& g, const std::vector<Sphere>& spheres,
                                                const std::vector<std::pair<std::size_t, Crossing>>& extra = {}) {
  std::vector<std::vector<Crossing>> tips(g.tip_count());
  for (const auto& s : spheres)
    for (std::size_t t = 0; t < g.tip_count(); ++t)
      if (const auto c = s.at(g.positions()[t])) tips[t].push_back(*c);
  for (const auto& [t, c] : extra) tips[t].push_back(c);
  for (auto& t : tips) std::sort(t.begin(), t.end(), [](const Crossing& a, const Crossing& b) { return a.front < b.front; });
  return tips;
}

BubbleFate fate(const awcc::ProbePairing& p, std::size_t k) {
  for (std::size_t f = 0; f < awcc::bubble_fate_count; ++f)
    if (p.fates[k][f] > 0) return static_cast<BubbleFate>(f);
  return BubbleFate::roc;  // none: cannot happen with one leading bubble
}

// A 4 mm sphere along x at `speed`, its line 0.5 mm off the leading tip in y
// and z: it pierces all four tips.
Sphere along_x(double speed, double t0 = 0.01) { return sphere_through({speed, 0, 0}, 4e-3, {0, 0.5e-3, 0.5e-3}, t0); }

awcc::ProbePairing pair(const std::vector<std::vector<Crossing>>& tips, const EventOptions& o = {},
                        std::optional<double> v_ref = kRef) {
  return awcc::pair_probe(ProbeGeometry(kSample), tips, o, v_ref);
}

}  // namespace pairing

TEST(PairProbe, TheSlowEndOfTheWindowIsProbeSpeedMinOfTheFirstVelocity) {
  using namespace pairing;
  const ProbeGeometry g(kSample);
  // Tip 1 straight behind: latest lag |S| / (0.5 V_ref) = 2 ms, i.e. 2.5 m/s.
  // Tips 2 and 3 (16.7 degrees off x, within the 30 degree cone): 2.09 ms.
  const auto inside = pair(crossings_of(g, {along_x(2.53)}));
  ASSERT_TRUE(inside.ok()) << inside.message;
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(fate(inside, k), BubbleFate::paired) << k;
  const auto outside = pair(crossings_of(g, {along_x(2.47)}));
  EXPECT_EQ(fate(outside, 0), BubbleFate::no_partner);
  EXPECT_EQ(fate(outside, 1), BubbleFate::paired) << "2.02 ms is inside tip 2's window";
  EXPECT_EQ(fate(outside, 2), BubbleFate::paired);
  // Two partners cannot be tested: listed, and no vector from them.
  EXPECT_FALSE(outside.bubbles.partner(0, 0));
  EXPECT_EQ(awcc::multi_tip(g, outside.bubbles, 1.0, no_statistics()).count(VectorFate::too_few_tips), 1);
  // The same bubble with a looser band pairs at every tip.
  EventOptions slower;
  slower.probe_speed_min = 0.45;
  const auto loose = pair(crossings_of(g, {along_x(2.47)}), slower);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(fate(loose, k), BubbleFate::paired) << k;
}

TEST(PairProbe, TheFastEndIsTheSpeedBandOfTheSolvedVector) {
  using namespace pairing;
  const ProbeGeometry g(kSample);
  // The window's short end is |S| cos(30 deg) / (2.5 V_ref) = 0.35 ms for tip
  // 1: a bubble at 12.6 m/s (0.40 ms) is in every window, but its vector is
  // above 2.5 V_ref = 12.5 m/s: not taken for one bubble.
  const auto fast = pair(crossings_of(g, {along_x(12.6)}));
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(fate(fast, k), BubbleFate::inconsistent) << k;
  const auto below = pair(crossings_of(g, {along_x(12.4)}));
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(fate(below, k), BubbleFate::paired) << k;
  const auto r = awcc::multi_tip(g, below.bubbles, 1.0, no_statistics());
  ASSERT_EQ(r.count(VectorFate::solved), 1);
  EXPECT_LT(relative(r.bubbles[0].velocity, {12.4, 0, 0}), 1e-9);
}

TEST(PairProbe, TheConeRefusesAVelocityTiltedBeyondProbeAngleMax) {
  using namespace pairing;
  const ProbeGeometry g(kSample);
  // A 20 mm sphere through the probe's middle, 5 m/s tilted towards +y: it
  // pierces every tip at 29 and 31 degrees, and its lags lie in every
  // window; only the angle of its vector decides.
  for (const double degrees : {29.0, 31.0}) {
    const double a = degrees * std::numbers::pi / 180.0;
    const Vec3 v{5.0 * std::cos(a), 5.0 * std::sin(a), 0.0};
    const auto p = pair(crossings_of(g, {sphere_through(v, 20e-3, {0, 0, 0}, 0.01)}));
    ASSERT_TRUE(p.ok());
    for (std::size_t k = 0; k < 3; ++k)
      EXPECT_EQ(fate(p, k), degrees < 30.0 ? BubbleFate::paired : BubbleFate::inconsistent) << degrees << " " << k;
  }
}

TEST(PairProbe, TwoCandidatesInAWindowAreRefusedNeverTheCloserTaken) {
  using namespace pairing;
  const ProbeGeometry g(kSample);
  const Sphere s = along_x(5.0);
  const Crossing own = *s.at(kSample[2]);
  // A second crossing at tip 2 after the bubble's own, both in the window
  // (1.0 ms and 1.6 ms against 2.09 ms).
  const Crossing other{own.front + 0.6e-3, own.rear + 0.6e-3, false};
  const auto p = pair(crossings_of(g, {s}, {{2, other}}));
  EXPECT_EQ(fate(p, 1), BubbleFate::ambiguous);
  EXPECT_FALSE(p.bubbles.partner(0, 1));
  EXPECT_EQ(fate(p, 0), BubbleFate::paired);
  EXPECT_EQ(fate(p, 2), BubbleFate::paired);
  // Beyond the window (2.2 ms) it is no candidate: the bubble pairs.
  const Crossing late{own.front + 1.2e-3, own.rear + 1.2e-3, false};
  const auto q = pair(crossings_of(g, {s}, {{2, late}}));
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(fate(q, k), BubbleFate::paired) << k;
}

TEST(PairProbe, PartnersThatAreNotOneBubbleAreRefusedAtEveryTip) {
  using namespace pairing;
  const ProbeGeometry g(kSample);
  // The bubble misses tip 2; another crossing there 0.4 ms after it would
  // have come: in the window, but the vector through it is tilted 53 degrees.
  const Sphere s = along_x(5.0);
  const Crossing own = *s.at(kSample[2]);
  auto tips = crossings_of(g, {s});
  tips[2] = {Crossing{own.front + 0.4e-3, own.rear + 0.4e-3, false}};
  const auto p = pair(tips);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(fate(p, k), BubbleFate::inconsistent) << k;
  EXPECT_EQ(awcc::multi_tip(g, p.bubbles, 1.0, no_statistics()).count(VectorFate::solved), 0);
}

TEST(PairProbe, DiametersThatDisagreeRefuseThePartnersAtTheMismatchLimit) {
  using namespace pairing;
  const ProbeGeometry g(kSample);
  // Tip 2's front 0.05 ms early: the vector moves little (in band and cone,
  // as the pairing at 1.01 times the mismatch shows), the diameters disagree.
  // (A chord lengthened about its centre changes both diameters alike.)
  const Sphere s = along_x(5.0);
  auto tips = crossings_of(g, {s});
  tips[2][0].front -= 0.05e-3;
  const auto& c = g.combinations()[0];
  awcc::detail::CombinationSolution sol;
  const std::array<const Crossing*, 3> at{&tips[1][0], &tips[2][0], &tips[3][0]};
  ASSERT_TRUE(awcc::detail::solve_combination(c, tips[0][0], at, VelocityAlgorithm::shen_nakamura, sol));
  const double mismatch =
      std::fabs(sol.diameter_front - sol.diameter_rear) / (0.5 * (sol.diameter_front + sol.diameter_rear));
  ASSERT_GT(mismatch, 0.01);
  for (const double limit : {0.99 * mismatch, 1.01 * mismatch}) {
    EventOptions o;
    o.probe_diameter_mismatch = limit;
    const auto p = pair(tips, o);
    for (std::size_t k = 0; k < 3; ++k)
      EXPECT_EQ(fate(p, k), limit < mismatch ? BubbleFate::inconsistent : BubbleFate::paired) << limit << " " << k;
  }
}

TEST(PairProbe, ATrailingCrossingChosenByTwoLeadingBubblesIsRefusedToBoth) {
  using namespace pairing;
  const ProbeGeometry g(kSample);
  // A second leading crossing ending 0.1 ms before the bubble's own, of the
  // same chord: its lags to the bubble's partners (1.85 ms) lie in its
  // windows too, and with the diameter check off they are one bubble for
  // it as well: both choose them.
  const Sphere s = along_x(5.0);
  const Crossing lead = *s.at(kSample[0]);
  const Crossing before{2.0 * lead.front - lead.rear - 0.1e-3, lead.front - 0.1e-3, false};
  EventOptions o;
  o.probe_diameter_mismatch = 1e9;
  const auto p = pair(crossings_of(g, {s}, {{0, before}}), o);
  ASSERT_EQ(p.bubbles.size(), 2u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(p.fates[k][static_cast<std::size_t>(BubbleFate::claimed_twice)], 2) << k;
    EXPECT_FALSE(p.bubbles.partner(0, k));
    EXPECT_FALSE(p.bubbles.partner(1, k));
  }
}

TEST(PairProbe, OfFiveTipsTheOneTipThatIsNotTheBubblesIsDropped) {
  using namespace pairing;
  std::vector<Vec3> five = kSample;
  five.push_back({5e-3, -1e-3, 0});
  const ProbeGeometry g(five);
  const Sphere s = along_x(5.0);
  auto tips = crossings_of(g, {s});
  ASSERT_EQ(tips[4].size(), 1u);
  tips[4][0].front += 0.4e-3;
  tips[4][0].rear += 0.4e-3;
  const auto p = awcc::pair_probe(g, tips, EventOptions{}, kRef);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(fate(p, k), BubbleFate::paired) << k;
  EXPECT_EQ(fate(p, 3), BubbleFate::inconsistent);
  const auto r = awcc::multi_tip(g, p.bubbles, 1.0, no_statistics());
  ASSERT_EQ(r.count(VectorFate::solved), 1);
  EXPECT_LT(relative(r.bubbles[0].velocity, {5, 0, 0}), 1e-9);
}

TEST(PairProbe, WithoutAFirstVelocityThePairingIsRefused) {
  using namespace pairing;
  const ProbeGeometry g(kSample);
  const auto tips = crossings_of(g, {along_x(5.0)});
  for (const std::optional<double> v : {std::optional<double>{}, std::optional<double>{0.0}}) {
    const auto p = pair(tips, {}, v);
    EXPECT_EQ(p.status, awcc::EventStatus::no_first_velocity);
    EXPECT_FALSE(p.message.empty());
    EXPECT_EQ(p.bubbles.size(), 0u);
  }
  EventOptions bad;
  bad.probe_angle_max = 90.0;
  EXPECT_THROW((void)pair(tips, bad), awcc::OptionError);
}
