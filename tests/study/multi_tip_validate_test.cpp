// study/multi_tip_validate.hpp: the matching of estimated bubbles to the
// truth rows (constructed cases whose answer is known, a planted mis-pairing
// among them), and the validation of a short clean four-tip scene.
#include <gtest/gtest.h>

#include "awcc/clean_scene.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "awcc/errors.hpp"
#include "study/multi_tip_validate.hpp"

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A truth table of two tips (0 leading, 1 trailing) from each row's fronts
// (NaN: the bubble never reached that tip).
synth::BubbleTruth two_tip_truth(const std::vector<std::pair<double, double>>& fronts) {
  synth::BubbleTruth t;
  t.tip_count = 2;
  for (std::size_t r = 0; r < fronts.size(); ++r) {
    t.id.push_back(r);
    t.diameter.push_back(4e-3);
    t.semi_axes.push_back({2e-3, 2e-3, 2e-3});
    t.velocity.push_back({2.0, 0.0, 0.0});
    t.interaction_start.push_back(fronts[r].first);
    t.interaction_end.push_back(fronts[r].first + 2e-3);
    t.extra_passes.push_back(0);
    for (const double front : {fronts[r].first, fronts[r].second}) {
      synth::TipPierce p;
      p.front = front;
      p.rear = std::isnan(front) ? kNaN : front + 1e-3;
      t.pierces.push_back(p);
    }
  }
  return t;
}

awcc::Crossing at(double front) { return {front, front + 1e-3, false}; }

TEST(MatchTruthRows, EachCrossingFindsTheRowWhoseFrontAtThatTipIsWithinTheTolerance) {
  // Row 1 reached tip 1 only: its front there (2.0) must not match a
  // leading crossing at 2.0, which is row 3's.
  const auto truth = two_tip_truth({{1.0, 1.001}, {kNaN, 2.0}, {1.5, 1.501}, {2.0 + 4e-6, 2.001}});
  const double tolerance = 1e-5;
  const std::vector<awcc::Crossing> crossings{at(1.0 + 3e-6), at(1.5 - 2e-5), at(2.0), at(3.0)};
  const auto rows = study::match_truth_rows(truth, 0, crossings, tolerance);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0], std::optional<std::size_t>(0));
  EXPECT_FALSE(rows[1].has_value()) << "2e-5 s off is beyond the tolerance";
  EXPECT_EQ(rows[2], std::optional<std::size_t>(3)) << "the leading tip's front, not the trailing tip's";
  EXPECT_FALSE(rows[3].has_value());
  // At tip 1 the same crossing times find the rows by their tip-1 fronts.
  const auto at_tip1 = study::match_truth_rows(truth, 1, std::vector<awcc::Crossing>{at(2.0)}, tolerance);
  EXPECT_EQ(at_tip1[0], std::optional<std::size_t>(1));
  EXPECT_THROW((void)study::match_truth_rows(truth, 2, crossings, tolerance), std::invalid_argument);
}

TEST(MatchTruthRows, TheClosestOfTwoRowsWithinTheToleranceIsTaken) {
  const auto truth = two_tip_truth({{1.0, 1.001}, {1.0 + 8e-6, 1.002}});
  const auto rows = study::match_truth_rows(truth, 0, std::vector<awcc::Crossing>{at(1.0 + 5e-6), at(1.0 + 3e-6)},
                                            1e-5);
  EXPECT_EQ(rows[0], std::optional<std::size_t>(1));
  EXPECT_EQ(rows[1], std::optional<std::size_t>(0));
}

TEST(ScorePartners, APlantedMisPairingIsCountedWrongAndAMissedPartnerLowersTheYield) {
  // Rows 0, 1 and 3 reached the trailing tip, row 2 did not.
  const auto truth = two_tip_truth({{1.0, 1.001}, {1.01, 1.011}, {1.02, kNaN}, {1.03, 1.031}, {1.04, 1.041}});
  const double tolerance = 1e-5;
  const std::vector<std::optional<std::size_t>> rows{0, 1, 2, 3, std::nullopt};
  const std::vector<std::optional<double>> partners{
      1.001 + 2e-6,  // bubble 0: its own partner, within the tolerance
      1.031,         // bubble 1: row 3's partner, planted (a mis-pairing)
      1.021,         // bubble 2: its truth never reached the tip, so any partner is another bubble
      std::nullopt,  // bubble 3: missed
      1.041,         // bubble 4: no truth row, so the partner cannot be confirmed
  };
  const auto s = study::score_partners(truth, rows, 1, partners, tolerance);
  EXPECT_EQ(s.partners, 4);
  EXPECT_EQ(s.wrong, 3);
  EXPECT_EQ(s.truth_pairs, 3);  // rows 0, 1 and 3
  EXPECT_EQ(s.found, 1);
  EXPECT_DOUBLE_EQ(s.error_fraction(), 0.75);
  EXPECT_DOUBLE_EQ(s.yield(), 1.0 / 3.0);

  // Putting the planted partner right removes exactly one error and adds one find.
  auto fixed = partners;
  fixed[1] = 1.011;
  const auto f = study::score_partners(truth, rows, 1, fixed, tolerance);
  EXPECT_EQ(f.wrong, s.wrong - 1);
  EXPECT_EQ(f.found, s.found + 1);

  // No partners: NaN fractions, not zeros.
  const std::vector<std::optional<double>> none(rows.size());
  const auto n = study::score_partners(truth, rows, 1, none, tolerance);
  EXPECT_TRUE(std::isnan(n.error_fraction()));
  EXPECT_EQ(n.truth_pairs, 3);
  EXPECT_DOUBLE_EQ(n.yield(), 0.0);
  EXPECT_THROW((void)study::score_partners(truth, rows, 1, std::vector<std::optional<double>>(2), tolerance),
               std::invalid_argument);
}

TEST(Compared, ErrorIsOverTheScaleAndEmptyWithoutAValue) {
  EXPECT_NEAR(*study::Compared({2.1, 2.0, 2.0}).error(), 0.05, 1e-15);
  EXPECT_NEAR(*study::Compared({0.1, 0.0, 2.0}).error(), 0.05, 1e-15);  // a transverse mean over the speed
  EXPECT_FALSE(study::Compared({std::nullopt, 2.0, 2.0}).error());
  EXPECT_FALSE(study::Compared({1.0, 0.0, 0.0}).error());
}

TEST(ValidateMultiTip, RefusesAProbeOfFewerThanFourTipsAndTipsInOnePlane) {
  synth::Scene s;
  s.duration = 0.1;
  EXPECT_THROW((void)study::validate_multi_tip(s), std::invalid_argument);
  // Every trailing tip in the plane z = 0 with the leading tip.
  s.tips = {{0, 0, 0}, {2e-3, 0, 0}, {2e-3, 1e-3, 0}, {2e-3, -1e-3, 0}};
  try {
    (void)study::validate_multi_tip(s);
    FAIL() << "a probe with every tip in one plane was validated";
  } catch (const awcc::OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("tip"), std::string::npos) << e.what();
  }
}

}  // namespace

namespace {

// The clean four-tip scene (tests/awcc/clean_scene.hpp), shorter.
synth::Scene clean_four_tip(double duration) { return pdp_test::clean_four_tip_scene(duration); }

// Bounds derived for this scene (fs = 200 kHz, |S_0k| = 2-2.24 mm, U = 2 m/s):
//  - timing: each interface is within half a sample of the truth, uniform, so
//    the mean of a front and a rear lag has sd 1 / (fs sqrt(12)) = 1.44 us,
//    0.144 % of the ~1 ms lag; the solver maps the three lags' relative
//    errors to w = V / |V|^2 through A_0^-1, whose Frobenius norm for this
//    combination (rows (1,0,0), (2,1,0)/sqrt5, (2,0,1)/sqrt5) is sqrt(19) =
//    4.36: relative vector error rms <= 4.36 x 0.144 % = 0.63 %, and a median
//    is at most sqrt(2) x the rms (Markov on the square): 0.89 %. The bubble's
//    velocity changes over its ~5 ms passage (sigma_u sqrt(2 tau / T) = 0.105
//    x 0.1 m/s, 0.5 % of U), which the rigid-translation solvers cannot see:
//    at most 0.5 % more. Bound: 1.5 %.
//  - statistics: the accepted bubbles sample the one realised series, so a
//    mean component is within 4 sigma_i / sqrt(N) of the realised one and a
//    Tu within 4 / sqrt(2N) relatively (Gaussian rms; the equal-time
//    arrivals sample the slow series more evenly than at random, so these
//    are conservative).
TEST(ValidateMultiTip, ACleanFourTipSceneMeetsItsDerivedBounds) {
  const auto v = study::validate_multi_tip(clean_four_tip(30.0));
  SCOPED_TRACE(study::multi_tip_report(v));
  // Every leading crossing is a truth bubble's (no two bubbles touch at
  // c = 0.05 within a sample).
  EXPECT_EQ(v.leading_matched, v.leading_bubbles);
  ASSERT_GT(v.leading_bubbles, 400);
  ASSERT_EQ(v.pairing.size(), 3u);

  // Tip 1 lies straight downstream: a leading bubble's own partner arrives
  // there first (its centre lag is the shortest), so a wrong partner needs a
  // truth bubble that missed tip 1.
  EXPECT_LE(v.pairing[0].wrong, v.leading_matched - v.pairing[0].truth_pairs);
  // The dual tip's event detection pairs the same two tips by Kramer's
  // rule, not the probe's joint one (awcc/multi_tip.hpp, pair_probe), so
  // the partners may differ in number; the same argument bounds its wrong
  // ones, and neither can find more than the truth holds.
  EXPECT_EQ(v.dual.trailing_tip, 1u);
  EXPECT_EQ(v.dual.pairing.truth_pairs, v.pairing[0].truth_pairs);
  EXPECT_LE(v.dual.pairing.wrong, v.leading_matched - v.pairing[0].truth_pairs);
  EXPECT_LE(v.dual.pairing.found, v.dual.pairing.truth_pairs);
  // pdp process's processing: the probe declared tip k on channel k, the pair
  // first, so its tips are in the scene's order.
  ASSERT_TRUE(v.dual.processed.probe);
  EXPECT_EQ(v.dual.processed.probe->channels, (std::vector<int>{0, 1, 2, 3}));

  ASSERT_EQ(v.algorithms.size(), 2u);
  const auto& sn = v.algorithms[0];
  const auto& tian = v.algorithms[1];
  ASSERT_TRUE(sn.result.ok()) << sn.result.message;
  ASSERT_TRUE(tian.result.ok()) << tian.result.message;
  const double n = static_cast<double>(sn.result.bubbles_accepted);
  ASSERT_GT(n, 200.0);
  EXPECT_LT(sn.vector_error.median, 0.015);
  EXPECT_LE(sn.speed_error.median, sn.vector_error.median * (1.0 + 1e-12) + 1e-15)
      << "||v| - |u|| <= |v - u| bubble by bubble, so for the medians too";
  const double speed = std::hypot(v.realised_velocity[0], v.realised_velocity[1], v.realised_velocity[2]);
  for (std::size_t i = 0; i < 3; ++i) {
    const double sigma = v.realised_turbulence_intensity[i] * speed;
    ASSERT_TRUE(sn.mean_velocity[i].error());
    EXPECT_LT(std::fabs(*sn.mean_velocity[i].error()), 4.0 * sigma / std::sqrt(n) / speed) << "component " << i;
    ASSERT_TRUE(sn.turbulence_intensity[i].error());
    EXPECT_LT(std::fabs(*sn.turbulence_intensity[i].error()), 4.0 / std::sqrt(2.0 * n)) << "component " << i;
  }
  // The accepted bubbles' true vectors average to the realised mean within
  // the same sampling bound, and a mis-paired accepted bubble has a wrong
  // partner: no more of them than wrong partners.
  const double sigma_x = v.realised_turbulence_intensity[0] * speed;
  ASSERT_TRUE(sn.selected_velocity[0].error());
  EXPECT_LT(std::fabs(*sn.selected_velocity[0].error()), 4.0 * sigma_x / std::sqrt(n) / speed);
  EXPECT_LE(sn.accepted_mispaired, v.pairing_total.wrong);
  EXPECT_GE(sn.mispaired_weight_share, 0.0);
  EXPECT_LE(sn.mispaired_weight_share, 1.0);

  // Tian et al. solve the same linear system as Shen & Nakamura
  // (awcc/multi_tip.hpp): the same vector per bubble, to rounding, and no
  // interfacial area.
  ASSERT_EQ(sn.result.bubbles.size(), tian.result.bubbles.size());
  for (std::size_t h = 0; h < sn.result.bubbles.size(); ++h) {
    const auto& a = sn.result.bubbles[h];
    const auto& b = tian.result.bubbles[h];
    ASSERT_EQ(a.fate, b.fate) << "bubble " << h;
    if (a.fate != awcc::VectorFate::solved) continue;
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(a.velocity[i], b.velocity[i], 1e-9 * speed) << "bubble " << h;
  }
  EXPECT_EQ(tian.diameter_error.count, 0);
  // A result within the bounds above is not flagged: the caution's checks
  // (awcc/multi_tip.hpp) cannot fire (no outlier rejected, 72 % of the
  // leading bubbles accepted, the mean of 1/|v| over the median's inverse
  // exp(Tu^2 / 2) = 1.001 for log-normal speeds, limit 1.25), FSCC finds the
  // tips in order, and the streamwise mean against FSCC's velocity is a
  // comparison at 95 % whose false alarm rate is at most 5 % (one seed,
  // fixed).
  EXPECT_EQ(sn.quality, awcc::AwccQuality::ok) << sn.quality_reason;
  EXPECT_EQ(tian.quality, awcc::AwccQuality::ok) << tian.quality_reason;
  // The sum over the paired bubbles misses the bubbles without a vector
  // (156 of 562 here), and they are the off-centre ones of largest
  // 1 / |V . n| (awcc/multi_tip.hpp): below the all-bubbles estimator.
  ASSERT_TRUE(sn.interfacial_area_paired.value);
  EXPECT_LT(*sn.interfacial_area_paired.value, *sn.interfacial_area.value);
  EXPECT_FALSE(tian.interfacial_area_paired.value) << "Tian et al. give no normals";
  // The interfacial area needs the speeds only (awcc/multi_tip.hpp): both algorithms give the same.
  ASSERT_TRUE(tian.interfacial_area.value && sn.interfacial_area.value);
  EXPECT_NEAR(*tian.interfacial_area.value, *sn.interfacial_area.value, 1e-9 * *sn.interfacial_area.value);

  // Event detection on the aligned pair: u_h = |v|^2 / v_x, above v_x by
  // (v_y^2 + v_z^2) / v_x, on average U (Tu_y^2 + Tu_z^2) = 0.125 % of U;
  // the centre lag's timing error is 0.144 % rms (a median at most sqrt(2)
  // times it, 0.2 %). Per bubble: median below 0.5 %. The mean: that bias
  // plus 4 sigma_x / sqrt(N).
  const auto& d = v.dual;
  ASSERT_TRUE(d.events.ok()) << d.events.message;
  EXPECT_LT(d.velocity_error.median, 0.005);
  const double n_ed = static_cast<double>(d.events.bubbles_paired);
  const double tu_y = v.realised_turbulence_intensity[1], tu_z = v.realised_turbulence_intensity[2];
  EXPECT_LT(std::fabs(*d.ed_velocity.error()),
            tu_y * tu_y + tu_z * tu_z + 4.0 * v.realised_turbulence_intensity[0] / std::sqrt(n_ed));
  EXPECT_LT(std::fabs(*d.ed_turbulence_intensity.error()), 4.0 / std::sqrt(2.0 * n_ed));
  // AWCC ran on the same pair and gave a velocity.
  ASSERT_TRUE(d.processed.awcc);
  EXPECT_TRUE(d.awcc_velocity.value);

  // The JSON carries what the report says.
  const auto j = study::multi_tip_to_json(v);
  EXPECT_EQ(j["pairing"]["all"]["wrong"], v.pairing_total.wrong);
  EXPECT_EQ(j["algorithms"]["shen-nakamura"]["speed_error"]["median"], sn.speed_error.median);
  EXPECT_EQ(j["dual_tip"]["tips"][1], 1);
  EXPECT_EQ(j["algorithms"]["shen-nakamura"]["quality"], "ok");
  EXPECT_TRUE(j["algorithms"]["shen-nakamura"]["quality_reason"].is_null());
  EXPECT_EQ(j["pairing"]["status"], "ok");
  EXPECT_NE(study::multi_tip_report(v).find("pdp's quality: ok"), std::string::npos);
}

// Wrong and flagged: the study's smallest probe (docs/validation.md, "Tip
// geometry"): trailing tips 0.4 mm behind, two offset l = 0.2 mm, 4 mm
// spheres at U = 5 m/s, Tu_x = 0.05, Tu_y = Tu_z = 0.0125, fs = 200 kHz. A
// lateral velocity v_y shifts the lag of an offset tip by l v_y / U^2: for
// sigma_y = 0.0625 m/s that is 0.5 us rms, a tenth of a sample, so the
// lags of most bubbles at the offset and the straight tips round alike and
// their v_y is exactly 0 (steps of U^2 / (fs l) = 0.625 m/s, ten sigma_y).
// The outlier cutoff's spread is then zero: it keeps the v_y = 0 bubbles
// and rejects the rest, so Tu_y comes out far too low, and pdp must say so
// (the caution: the cutoff rejected more than half the solved vectors).
TEST(ValidateMultiTip, LateralComponentsBelowTheTimingResolutionAreWrongAndFlagged) {
  synth::Scene s;
  s.velocity = 5.0;
  s.tu = 0.05;
  s.tu_y = s.tu_z = 0.0125;
  s.time_scale = 0.05;
  s.void_fraction = 0.1;
  s.bubble_diameter = 4e-3;
  s.tips = {{0, 0, 0}, {0.4e-3, 0, 0}, {0.4e-3, 0.2e-3, 0}, {0.4e-3, 0, 0.2e-3}};
  s.fs = 200e3;
  s.duration = 5.0;
  s.arrival = synth::ArrivalRule::equal_space;
  s.seed = 3030;
  const auto v = study::validate_multi_tip(s);
  SCOPED_TRACE(study::multi_tip_report(v));
  ASSERT_EQ(v.algorithms.size(), 2u);
  for (const auto& a : v.algorithms) {
    ASSERT_TRUE(a.result.ok()) << a.result.message;
    ASSERT_TRUE(a.turbulence_intensity[1].error());
    EXPECT_LT(*a.turbulence_intensity[1].error(), -0.5) << "Tu_y is resolved after all: the test lost its case";
    EXPECT_NE(a.quality, awcc::AwccQuality::ok) << "a Tu_y off by " << 100.0 * *a.turbulence_intensity[1].error()
                                                 << " % was not flagged";
    EXPECT_NE(a.quality_reason.find("outlier cutoff"), std::string::npos) << a.quality_reason;
  }
}

TEST(ValidateMultiTip, RepeatsDeriveTheirSeedsAndSummariseEachError) {
  const auto runs = study::validate_multi_tip_repeats(clean_four_tip(5.0), {}, 2);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_NE(runs[0].scene.seed, runs[1].scene.seed);
  const auto summary = study::summarise_multi_tip(runs);
  ASSERT_FALSE(summary.empty());
  EXPECT_EQ(summary.front().key, "pairing_error");
  EXPECT_EQ(summary.front().summary.count, 2);
  EXPECT_NEAR(summary.front().summary.mean,
              0.5 * (runs[0].pairing_total.error_fraction() + runs[1].pairing_total.error_fraction()), 1e-15);
}

}  // namespace
