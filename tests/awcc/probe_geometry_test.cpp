// The multi-tip probe's geometry (awcc/probe_geometry.hpp): the leading tip,
// S_0k, c_0k, the combinations' conditioning against closed forms, and every
// refusal naming the tip at fault (issue 30: tips in one plane, a tip listed
// twice).
#include "awcc/probe_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "probe_builders.hpp"

namespace {

using awcc::ProbeGeometry;
using awcc::Vec3;
using pdp_test::cone_probe;

constexpr double kLimit = 0.05;  // MultiTipOptions' default conditioning-min

// samples/four-tip.toml's probe, in metres.
std::vector<Vec3> sample_probe() { return {{0, 0, 0}, {5e-3, 0, 0}, {5e-3, 1.5e-3, 0}, {5e-3, 0, 1.5e-3}}; }

TEST(ProbeGeometry, TheMostUpstreamTipLeadsAndTheVectorsAreFromIt) {
  // Listed out of order: tip 2 is the most upstream.
  const ProbeGeometry g({{5e-3, 0, 0}, {5e-3, 1.5e-3, 0}, {-1e-3, 0.5e-3, 0}, {5e-3, 0, 1.5e-3}});
  ASSERT_TRUE(g.check(kLimit).ok()) << g.check(kLimit).message;
  EXPECT_EQ(g.leading(), 2u);
  EXPECT_EQ(g.trailing_tips(), (std::vector<std::size_t>{0, 1, 3}));
  const Vec3 s = g.offset(1);  // tip 1 - tip 2
  EXPECT_DOUBLE_EQ(s[0], 6e-3);
  EXPECT_DOUBLE_EQ(s[1], 1e-3);
  EXPECT_DOUBLE_EQ(g.distance(1), std::sqrt(37.0) * 1e-3);
  EXPECT_DOUBLE_EQ(g.cosines(1)[0], 6.0 / std::sqrt(37.0));
  EXPECT_EQ(g.combinations().size(), 1u);
}

TEST(ProbeGeometry, ConditioningIsTheDeterminantOfTheDirectionCosines) {
  // The sample probe: rows (1,0,0), (5,1.5,0)/L, (5,0,1.5)/L, L^2 = 27.25:
  // det = 1.5^2 / 27.25.
  const ProbeGeometry sample(sample_probe());
  ASSERT_EQ(sample.combinations().size(), 1u);
  EXPECT_NEAR(sample.combinations()[0].conditioning(), 2.25 / 27.25, 1e-15);
  EXPECT_TRUE(sample.check(kLimit).ok()) << "the default limit must admit pdp's own four-tip sample";
  // A cone: closed form, independent of the scale (mm or m alike).
  for (double scale : {1e-3, 1.0}) {
    const ProbeGeometry cone(cone_probe(3, 2.0 * scale, 1.0 * scale, 0.3));
    EXPECT_NEAR(cone.combinations()[0].conditioning(), pdp_test::three_tip_cone_conditioning(2.0, 1.0), 1e-14);
  }
  // Orthogonal directions: 1, the most any three unit vectors reach.
  const ProbeGeometry orthogonal({{0, 0, 0}, {1e-3, 0, 0}, {0, 1e-3, 0}, {0, 0, 1e-3}}, 0);
  EXPECT_NEAR(orthogonal.combinations()[0].conditioning(), 1.0, 1e-15);
  // The stored inverses are inverses.
  const auto& c = sample.combinations()[0];
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      double p = 0.0;
      for (std::size_t k = 0; k < 3; ++k) p += c.cosines[i][k] * c.inverse_cosines[k][j];
      EXPECT_NEAR(p, i == j ? 1.0 : 0.0, 1e-14);
    }
  }
}

TEST(ProbeGeometry, FiveTipsGiveEveryCombinationOfThreeTrailingTips) {
  const ProbeGeometry g(cone_probe(4, 2e-3, 1e-3));
  ASSERT_EQ(g.combinations().size(), 4u);
  EXPECT_EQ(g.combinations()[0].trailing, (std::array<std::size_t, 3>{0, 1, 2}));
  EXPECT_EQ(g.combinations()[3].trailing, (std::array<std::size_t, 3>{1, 2, 3}));
}

TEST(ProbeGeometry, ConditioningAtAndAroundTheLimit) {
  for (double factor : {0.999, 1.0, 1.001}) {
    const double a = pdp_test::cone_angle_for(factor * kLimit);
    const ProbeGeometry g(cone_probe(3, 2e-3 * std::cos(a), 2e-3 * std::sin(a)));
    const double det = g.combinations()[0].conditioning();
    EXPECT_NEAR(det, factor * kLimit, 1e-12);
    const auto v = g.check(kLimit);
    if (factor > 1.0) {
      EXPECT_TRUE(v.ok()) << v.message;
    }
    if (factor < 1.0) {
      ASSERT_FALSE(v.ok());
      EXPECT_NE(v.message.find("tips 1, 2 and 3"), std::string::npos) << v.message;
      EXPECT_NE(v.message.find("conditioning-min"), std::string::npos) << v.message;
      EXPECT_EQ(v.quantity, "tips,conditioning-min");
    }
    // At the limit itself the combination is admitted: only below it is one skipped.
    EXPECT_TRUE(g.check(det).ok());
  }
}

TEST(ProbeGeometry, TipsInOnePlaneAreRefusedNamingThem) {
  // Every tip in the plane z = 0 (the leading one too).
  const ProbeGeometry flat({{0, 0, 0}, {2e-3, 1e-3, 0}, {2e-3, -1e-3, 0}, {3e-3, 0, 0}});
  const auto v = flat.check(kLimit);
  ASSERT_FALSE(v.ok());
  EXPECT_EQ(v.quantity, "tips");
  EXPECT_NE(v.message.find("tips 0, 1, 2 and 3 lie in one plane"), std::string::npos) << v.message;
  EXPECT_NE(v.message.find("leading tip 0"), std::string::npos) << v.message;
  // Trailing tips in a tilted plane through the leading tip.
  const ProbeGeometry tilted({{0, 0, 0}, {2e-3, 1e-3, 1e-3}, {2e-3, -1e-3, -1e-3}, {3e-3, 2e-3, 2e-3}});
  EXPECT_NE(tilted.check(kLimit).message.find("lie in one plane"), std::string::npos);
}

TEST(ProbeGeometry, ATipListedTwiceIsRefusedNamingBoth) {
  auto tips = sample_probe();
  tips.push_back(tips[2]);
  const auto v = ProbeGeometry(tips).check(kLimit);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.message.find("tips 2 and 4 are at the same position (5, 1.5, 0) mm"), std::string::npos) << v.message;
  EXPECT_NE(v.message.find("listed twice"), std::string::npos);
}

TEST(ProbeGeometry, OtherRefusals) {
  const auto three = ProbeGeometry({{0, 0, 0}, {1e-3, 0, 0}, {1e-3, 1e-3, 0}}).check(kLimit);
  EXPECT_NE(three.message.find("3 tips given: a 3-D velocity needs at least 4 tips"), std::string::npos)
      << three.message;
  auto tips = sample_probe();
  tips[3][1] = std::numeric_limits<double>::quiet_NaN();
  const auto nan = ProbeGeometry(tips).check(kLimit);
  EXPECT_NE(nan.message.find("tip 3 has a coordinate that is not a finite number"), std::string::npos) << nan.message;
  // Two tips tie for the most upstream: name the leading tip.
  const ProbeGeometry tie({{0, 0, 0}, {0, 1e-3, 0}, {2e-3, 0, 1e-3}, {2e-3, 1e-3, -1e-3}});
  EXPECT_NE(tie.check(kLimit).message.find("tips 0 and 1 are both the most upstream"), std::string::npos)
      << tie.check(kLimit).message;
  // Naming it resolves the tie.
  EXPECT_TRUE(ProbeGeometry({{0, 0, 0}, {0, 1e-3, 0}, {2e-3, 0, 1e-3}, {2e-3, 1e-3, -1e-3}}, 0).check(kLimit).ok());
  EXPECT_NE(ProbeGeometry(sample_probe(), 7).check(kLimit).message.find("leading tip 7 is not one of the 4 tips"),
            std::string::npos);
}

}  // namespace
