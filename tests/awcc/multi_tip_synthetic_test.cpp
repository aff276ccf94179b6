// The multi-tip chain end to end on a synthetic four-tip probe with known
// truth per bubble (synth/bubble_truth.hpp): crossings of each tip's signal
// (awcc/interface_times.hpp) -> event detection's pairing of the leading tip
// with each trailing tip (pair_probe) -> Shen & Nakamura per bubble and the
// vector statistics (multi_tip). The scene is clean (METHOD 11.7: large
// spheres, weak turbulence with a long time scale), where the issue asks for
// pairing errors under 1 %, a median per-bubble speed error under 2 % and a
// mean vector within 2 % of the realised one, and the interfacial area
// within 5 % of 6 c / d_b. Then pdp's four-tip sample, where pairing each
// trailing tip alone took a quarter of the partners from other bubbles and
// the joint pairing must not (pair_probe's header, measured).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "awcc/fscc.hpp"
#include "awcc/interface_times.hpp"
#include "clean_scene.hpp"
#include "awcc/multi_tip.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

struct CleanProbe {
  synth::Synthesis synthesis;
  awcc::ProbeGeometry geometry;
  std::vector<std::vector<awcc::Crossing>> crossings;
};

CleanProbe clean_four_tip(double duration) {
  const synth::Scene s = pdp_test::clean_four_tip_scene(duration);
  synth::SynthesisOptions o;
  o.bubble_truth = true;
  CleanProbe p{synth::synthesise(s, o), {}, {}};
  std::vector<awcc::Vec3> tips;
  for (const auto& t : s.probe_tips()) tips.push_back({t.x, t.y, t.z});
  p.geometry = awcc::ProbeGeometry(tips);
  for (const auto& signal : p.synthesis.signals) p.crossings.push_back(awcc::crossings(signal));
  return p;
}

// pair_probe's first velocity, as pdp process gives it: FSCC's of the
// leading tip and the first trailing one.
double first_velocity(const synth::Synthesis& syn, const awcc::ProbeGeometry& g) {
  const auto f = awcc::fscc(syn.signals[g.leading()], syn.signals[g.trailing_tips()[0]], g.offset(0)[0]);
  EXPECT_TRUE(f.ok()) << f.message;
  return f.velocity;
}

// The truth row whose leading-tip front lies within one sample of `front`.
std::optional<std::size_t> truth_row(const synth::BubbleTruth& truth, std::size_t leading, double front, double fs) {
  std::optional<std::size_t> best;
  double gap = 1.0 / fs;
  for (std::size_t r = 0; r < truth.size(); ++r) {
    const auto& p = truth.pierce(r, leading);
    if (p.pierced() && std::fabs(p.front - front) <= gap) {
      gap = std::fabs(p.front - front);
      best = r;
    }
  }
  return best;
}

TEST(MultiTipSynthetic, ACleanFourTipSceneGivesEachBubbleItsOwnPartnersAndVelocity) {
  const CleanProbe p = clean_four_tip(120.0);
  ASSERT_TRUE(p.geometry.check(0.05).ok()) << p.geometry.check(0.05).message;
  const auto pairing =
      awcc::pair_probe(p.geometry, p.crossings, awcc::EventOptions{}, first_velocity(p.synthesis, p.geometry));
  ASSERT_TRUE(pairing.ok()) << pairing.message;
  const auto& truth = *p.synthesis.bubbles;
  const double fs = p.synthesis.signals[0].fs;
  const auto& trailing = p.geometry.trailing_tips();

  // Pairing: a partner is right when its front is the same bubble's front at
  // that tip (one sample of tolerance: both are the sampled true time).
  std::int64_t partners = 0, wrong = 0;
  for (std::size_t h = 0; h < pairing.bubbles.size(); ++h) {
    const auto row = truth_row(truth, p.geometry.leading(), pairing.bubbles.leading[h].front, fs);
    for (std::size_t k = 0; k < trailing.size(); ++k) {
      const auto& partner = pairing.bubbles.partner(h, k);
      if (!partner) continue;
      ++partners;
      const bool right = row && truth.pierce(*row, trailing[k]).pierced() &&
                         std::fabs(truth.pierce(*row, trailing[k]).front - partner->front) <= 1.0 / fs;
      wrong += right ? 0 : 1;
    }
  }
  std::printf("pairing: %lld of %lld partners wrong (%.2f %%)\n", static_cast<long long>(wrong),
              static_cast<long long>(partners), 100.0 * static_cast<double>(wrong) / static_cast<double>(partners));
  ASSERT_GT(partners, 1000);
  EXPECT_LT(static_cast<double>(wrong), 0.01 * static_cast<double>(partners)) << wrong << " of " << partners;

  const auto result = awcc::multi_tip(p.geometry, pairing.bubbles, 120.0);
  ASSERT_TRUE(result.ok()) << result.message;
  // Per bubble: the solved speed against the truth's interaction-mean speed.
  std::vector<double> errors;
  for (std::size_t h = 0; h < result.bubbles.size(); ++h) {
    const auto& b = result.bubbles[h];
    if (b.fate != awcc::VectorFate::solved) continue;
    const auto row = truth_row(truth, p.geometry.leading(), pairing.bubbles.leading[h].front, fs);
    if (!row) continue;
    const auto& v = truth.velocity[*row];
    const double true_speed = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    const double speed = std::hypot(b.velocity[0], b.velocity[1], b.velocity[2]);
    errors.push_back(std::fabs(speed - true_speed) / true_speed);
  }
  ASSERT_GT(errors.size(), 500u);
  std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2), errors.end());
  std::printf("%lld of %lld leading bubbles accepted; median speed error %.3f %% over %zu matched to the truth\n",
              static_cast<long long>(result.bubbles_accepted), static_cast<long long>(result.bubbles_total),
              100.0 * errors[errors.size() / 2], errors.size());
  EXPECT_LT(errors[errors.size() / 2], 0.02);

  // The mean vector against the realised fluid mean (the bubbles sample the
  // one uniform velocity series; duration weighting removes the bias towards
  // fast bubbles).
  const auto& realised = p.synthesis.truth.realised.mean_velocity;
  const double realised_speed = std::hypot(realised[0], realised[1], realised[2]);
  std::printf("mean vector (%.4f, %.4f, %.4f) m/s, realised (%.4f, %.4f, %.4f) m/s\n", result.velocity[0],
              result.velocity[1], result.velocity[2], realised[0], realised[1], realised[2]);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(result.velocity[static_cast<std::size_t>(i)], realised[static_cast<std::size_t>(i)],
                0.02 * realised_speed)
        << "component " << i;
  }
}

// The interfacial area of every complete bubble (multi_tip.hpp) on the clean
// scene, against 6 c / d_b and against the realised one at the leading tip.
// 1200 s give N_0 = 22,500 complete leading bubbles (19 a second), so:
//  - against 6 c / d_b the Poisson count error is 1 / sqrt(N_0) = 0.67 %;
//    the mean 1 / |v| adds at most 0.2 % (Tu_x = 0.05 over about T / 2T_x =
//    600 independent speeds); sd 0.7 %, and 5 % is 7 sd.
//  - The realised value (synth::TipTruth) is (1 / T) sum over the
//    interfaces that crossed the tip of 1 / |u . n|: N_0 is common to both,
//    what differs is its 1 / cos theta, of mean 2 and infinite variance
//    (P(1 / cos > x) = 1 / x^2). One pierce at cos theta < 1 / (2 N_0 d),
//    d = 5 %, adds 5 % on its own: probability 1 / (4 N_0 d^2) = 0.4 % a
//    record, and seed 11's first 600 s hold two at cos theta = 0.0012 (7 %
//    of that half's sum). Those pierces last less than a sample
//    (d_b cos theta / |u| < 1 / fs) and no probe sees them, so the
//    comparison is with the realised sum over the pierces that last a
//    sample or more: its 1 / cos theta is capped at G = fs d_b / |u| = 800,
//    one pierce adds at most G / (2 N_0) = 1.8 %, the variance of 1 / cos
//    is 2 ln G - 4 = 9.4 and the relative sd sqrt(9.4 / N_0) / 2 = 1.0 %:
//    5 % is 5 sd. TipTruth's value is printed beside it.
// The paired sum must stay below the realised one: it is a lower bound.
TEST(MultiTipSynthetic, InterfacialAreaOfTheCleanSceneIsSixCOverDWithinFivePercent) {
  const double duration = 1200.0;
  const CleanProbe p = clean_four_tip(duration);
  const auto pairing =
      awcc::pair_probe(p.geometry, p.crossings, awcc::EventOptions{}, first_velocity(p.synthesis, p.geometry));
  ASSERT_TRUE(pairing.ok()) << pairing.message;
  const double expected = p.synthesis.truth.expected_interfacial_area;
  const auto& leading_tip = p.synthesis.truth.tips[p.geometry.leading()];
  ASSERT_TRUE(leading_tip.interfacial_area);
  const auto& truth = *p.synthesis.bubbles;
  const double fs = p.synthesis.signals[0].fs;
  double shares = 0.0;
  for (std::size_t r = 0; r < truth.size(); ++r) {
    const auto& pierce = truth.pierce(r, p.geometry.leading());
    if (!pierce.pierced() || pierce.censored() || pierce.rear - pierce.front < 1.0 / fs) continue;
    const auto& v = truth.velocity[r];
    for (const auto& n : {pierce.front_normal, pierce.rear_normal}) {
      shares += 1.0 / std::fabs(v.x * n[0] + v.y * n[1] + v.z * n[2]);
    }
  }
  const double realised = shares / duration;
  std::printf("realised at the leading tip %.3f 1/m over the pierces of a sample or more (TipTruth: %.3f 1/m over "
              "all)\n",
              realised, *leading_tip.interfacial_area);
  for (auto algorithm : awcc::velocity_algorithms) {
    const auto r = awcc::multi_tip(p.geometry, pairing.bubbles, duration, awcc::MultiTipOptions{.algorithm = algorithm});
    ASSERT_TRUE(r.ok()) << r.message;
    ASSERT_TRUE(r.interfacial_area && r.interfacial_area_ci95);
    const double a = *r.interfacial_area;
    std::printf("%s: N_0 = %lld, %lld accepted; a = %.3f 1/m [%.3f, %.3f], 6c/d_b = %.3f, realised %.3f: %.4f and "
                "%.4f of them",
                std::string(to_string(algorithm)).c_str(), static_cast<long long>(r.bubbles_complete),
                static_cast<long long>(r.bubbles_accepted), a, r.interfacial_area_ci95->lower,
                r.interfacial_area_ci95->upper, expected, realised, a / expected, a / realised);
    if (r.interfacial_area_paired) {
      std::printf("; paired %.3f 1/m (%.4f)", *r.interfacial_area_paired, *r.interfacial_area_paired / expected);
      EXPECT_LT(*r.interfacial_area_paired, realised) << "a lower bound";
    }
    std::printf("\n");
    EXPECT_GT(r.bubbles_complete, 20000);
    EXPECT_NEAR(a / expected, 1.0, 0.05);
    EXPECT_NEAR(a / realised, 1.0, 0.05);
    EXPECT_TRUE(r.caution.empty()) << r.caution;
  }
}

// pdp's four-tip sample (samples/four-tip.toml: 4 mm spheres, c = 0.1,
// 5 m/s, Tu = 0.2, trailing tips 5 mm behind, two offset 1.5 mm; 10 s),
// where each trailing tip paired alone took 26 % of its partners from other
// bubbles (41 % of the accepted bubbles, mean vector 1.7 m/s). The joint
// pairing, against libsynth's truth:
//  - pairing errors (accepted bubbles with any partner from another bubble)
//    below 2 % of the accepted: the target; measured 3 of 345 (0.9 %) on the
//    sample's seed, 0-6 (at most 1.8 %) on seeds 1-12.
//  - the mean vector against the truth of the same accepted bubbles with the
//    same weights, within 2 % of |V|: it then differs only by each bubble's
//    timing error (one sample, 5 us, on 1 ms lags: 0.5 % a bubble, averaged
//    down over 360) and by the mis-paired ones (2 % of them at most, their
//    speeds off by at most 60 %: 1.2 %).
//  - the same against the duration-weighted truth of every complete
//    leading bubble matched to the truth: the accepted are a subset chosen
//    by where they pierce, and where a bubble pierces all four tips depends
//    a little on its path, so on its velocity: over seeds 1-12 (generator
//    version 2) the accepted bubbles' true mean speed was 1.8 % below all
//    bubbles' (sd 1.1 % between seeds; -3.2 % to +0.8 %), the mean vector
//    2.2 % below (sd 1.3 %, at most 3.3 % off). 5 % is that mean plus 2.2
//    sd: a pairing that took partners from other bubbles moves it by far
//    more (1.7 m/s, 35 %, paired tip by tip). An earlier bound of 3 %
//    assumed no selection at all, and failed on 4 of the 12 seeds.
//  - the realised time mean is not the comparison: the synthesiser's
//    arrivals are uniform in time, and the duration weighting (right for
//    arrivals in proportion to the speed) is biased by about -Tu_x^2 = -4 %
//    here; printed beside.
//  - no caution, and the interfacial area within 10 % of 6 c_tip / d_b,
//    c_tip = c (1 + Tu_x^2) the tip's void fraction under equal-time
//    arrivals (N_0 = 1856: Poisson sd 2.3 %, plus the mean 1 / |v| of 360
//    speeds at Tu 0.2: 1.1 %; 10 % is 4 sd).
TEST(MultiTipSynthetic, TheFourTipSamplePairsEachBubbleWithItsOwnPartners) {
  synth::Scene s;
  synth::load_scene_toml(pdp_test::source_dir() / "samples" / "four-tip.toml", s);
  synth::SynthesisOptions so;
  so.bubble_truth = true;
  const auto synthesis = synth::synthesise(s, so);
  std::vector<awcc::Vec3> tips;
  for (const auto& t : s.probe_tips()) tips.push_back({t.x, t.y, t.z});
  const awcc::ProbeGeometry geometry(tips);
  std::vector<std::vector<awcc::Crossing>> crossings;
  for (const auto& signal : synthesis.signals) crossings.push_back(awcc::crossings(signal));
  const auto pairing = awcc::pair_probe(geometry, crossings, awcc::EventOptions{}, first_velocity(synthesis, geometry));
  ASSERT_TRUE(pairing.ok()) << pairing.message;
  const auto r = awcc::multi_tip(geometry, pairing.bubbles, s.duration);
  ASSERT_TRUE(r.ok()) << r.message;
  const auto& truth = *synthesis.bubbles;
  const double fs = synthesis.signals[0].fs;
  const auto& trailing = geometry.trailing_tips();
  std::int64_t wrong = 0;
  double w_accepted = 0.0, w_all = 0.0;
  awcc::Vec3 accepted{}, all{};
  for (std::size_t h = 0; h < pairing.bubbles.size(); ++h) {
    const auto& lead = pairing.bubbles.leading[h];
    const auto row = truth_row(truth, geometry.leading(), lead.front, fs);
    if (lead.censored || !row) continue;
    const auto& v = truth.velocity[*row];
    const double span = truth.interaction_end[*row] - truth.interaction_start[*row];
    w_all += span;
    all = {all[0] + span * v.x, all[1] + span * v.y, all[2] + span * v.z};
    const auto& b = r.bubbles[h];
    if (b.fate != awcc::VectorFate::solved) continue;
    w_accepted += b.weight;
    accepted = {accepted[0] + b.weight * v.x, accepted[1] + b.weight * v.y, accepted[2] + b.weight * v.z};
    bool right = true;
    for (std::size_t k = 0; k < trailing.size(); ++k) {
      const auto& partner = pairing.bubbles.partner(h, k);
      const auto& pierce = truth.pierce(*row, trailing[k]);
      right = right && partner && pierce.pierced() && std::fabs(pierce.front - partner->front) <= 1.0 / fs;
    }
    wrong += right ? 0 : 1;
  }
  const auto& realised = synthesis.truth.realised.mean_velocity;
  std::printf("four-tip sample: %lld of %lld accepted bubbles mis-paired; mean vector (%.3f, %.3f, %.3f) m/s, truth of "
              "the accepted (%.3f, %.3f, %.3f), of all leading bubbles (%.3f, %.3f, %.3f), realised (%.3f, %.3f, "
              "%.3f); a = %.1f 1/m, 6 c_tip / d_b = %.1f 1/m\n",
              static_cast<long long>(wrong), static_cast<long long>(r.bubbles_accepted), r.velocity[0], r.velocity[1],
              r.velocity[2], accepted[0] / w_accepted, accepted[1] / w_accepted, accepted[2] / w_accepted,
              all[0] / w_all, all[1] / w_all, all[2] / w_all, realised[0], realised[1], realised[2],
              *r.interfacial_area, synthesis.truth.expected_interfacial_area * (1.0 + s.tu * s.tu));
  ASSERT_GT(r.bubbles_accepted, 200);
  EXPECT_LT(static_cast<double>(wrong), 0.02 * static_cast<double>(r.bubbles_accepted));
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_NEAR(r.velocity[j], accepted[j] / w_accepted, 0.02 * r.speed) << "component " << j;
    EXPECT_NEAR(r.velocity[j], all[j] / w_all, 0.05 * r.speed) << "component " << j;
  }
  EXPECT_TRUE(r.caution.empty()) << r.caution;
  EXPECT_NEAR(*r.interfacial_area / (synthesis.truth.expected_interfacial_area * (1.0 + s.tu * s.tu)), 1.0, 0.10);
}

}  // namespace
