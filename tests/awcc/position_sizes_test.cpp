// A position's bubble sizes and interfacial area (awcc/position_sizes.hpp)
// through the one processing path, against libsynth's drawn sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "awcc/errors.hpp"
#include "awcc/options.hpp"
#include "awcc/process.hpp"
#include "awcc/read_back.hpp"
#include "awcc/serialise.hpp"
#include "synth/synthesiser.hpp"

namespace {

using nlohmann::json;

// Spheres of log-normal sizes, c = 0.1, weak turbulence with a long time
// scale, aligned tips: the chord lengths are those of the spheres at nearly
// one velocity. 75 s give about 12,000 chords (sigma 0.6) to 22,000 (0.3).
synth::Scene lognormal_scene(double sigma, std::uint64_t seed) {
  synth::Scene s;
  s.velocity = 5.0;
  s.tu = 0.05;
  s.tu_y = s.tu_z = 0.025;
  s.time_scale = 1.0;
  s.void_fraction = 0.1;
  s.bubble_diameter = 2e-3;
  s.diameter_log_sd = sigma;
  s.dy = 0.0;
  s.fs = 100e3;
  s.duration = 75.0;
  s.seed = seed;
  return s;
}

// The drawn number distribution: d = d_b exp(sigma z), z standard normal
// truncated to |z| <= 3 (libsynth's synthesiser.cpp). Its median is d_b
// (the truncation is symmetric); d32 = E[d^3] / E[d^2], E[d^k] = d_b^k
// int_-3^3 phi(z) e^(k sigma z) dz / int_-3^3 phi = d_b^k e^(k^2 sigma^2 / 2)
// (Phi(3 - k sigma) - Phi(-3 - k sigma)) / (Phi(3) - Phi(-3)) exactly.
double drawn_sauter(double median, double sigma) {
  const auto Phi = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
  const auto moment = [&](double k) {
    return std::pow(median, k) * std::exp(0.5 * k * k * sigma * sigma) * (Phi(3.0 - k * sigma) - Phi(-3.0 - k * sigma));
  };
  return moment(3.0) / moment(2.0);
}

awcc::ProcessResult process(const synth::Scene& s, bool events) {
  const auto syn = synth::synthesise(s);
  awcc::BinarisedRecording b;
  b.info.fs = s.fs;
  b.info.frames = syn.signals[0].sample_count;
  b.info.channels = 2;
  b.leading = syn.signals[0];
  b.trailing = syn.signals[1];
  awcc::ProcessOptions o;
  o.dx = s.dx;
  o.events = events;
  return awcc::process_binarised(b, o);
}

class LogNormalSizes : public ::testing::TestWithParam<double> {};

TEST_P(LogNormalSizes, MedianAndSauterWithinTenPercentOfTheDrawnPopulation) {
  // The inversion's own spread at 5,000 chords is 1.1-3.6 % (median) and
  // 0.6-1.1 % (d32) per draw (size_distribution.hpp); here 12,000-25,000
  // chords at their window's velocity (Tu 0.05 adds a 5 % spread to each
  // length, which widens the inverted distribution by a factor sqrt(1 +
  // 0.05^2 / sigma^2): 1.4 % at sigma 0.3) and samples of 20 um (the floor
  // chord is ~10 samples): 10 % is several standard deviations from both.
  const double sigma = GetParam();
  const auto s = lognormal_scene(sigma, 31);
  const auto r = process(s, false);
  ASSERT_TRUE(r.sizes);
  const auto& z = *r.sizes;
  ASSERT_TRUE(z.ok()) << z.message;
  ASSERT_EQ(z.phase, awcc::DispersedPhase::bubbles);
  EXPECT_GT(z.distribution.chords_used, 10000);
  EXPECT_EQ(z.count(awcc::ChordVelocity::bubble), 0);
  EXPECT_GT(z.count(awcc::ChordVelocity::window), z.chords_given * 9 / 10);
  EXPECT_NEAR(z.distribution.median / s.bubble_diameter, 1.0, 0.10);
  EXPECT_NEAR(z.distribution.d32 / drawn_sauter(s.bubble_diameter, sigma), 1.0, 0.10);
  // Moments ordered as every distribution's are.
  const auto& d = z.distribution;
  EXPECT_LT(d.d10, d.d20);
  EXPECT_LT(d.d20, d.d30);
  EXPECT_LT(d.d30, d.d32);
}

INSTANTIATE_TEST_SUITE_P(Sigma, LogNormalSizes, ::testing::Values(0.3, 0.6));

TEST(PositionSizes, WithEventDetectionTheChordsTakeTheirBubblesVelocities) {
  // On aligned tips and large-ish bubbles, Kramer's pairing pairs most
  // bubbles and agrees with FSCC (quality ok): each paired bubble's chord
  // then has its own velocity, the rest their window's.
  auto s = lognormal_scene(0.3, 7);
  s.duration = 10.0;
  const auto r = process(s, true);
  ASSERT_TRUE(r.events);
  ASSERT_EQ(r.events->quality, awcc::AwccQuality::ok) << r.events->quality_reason;
  const auto& z = *r.sizes;
  // Every paired complete bubble is counted per bubble, exactly.
  std::int64_t paired_complete = 0;
  const auto& iv = r.events->bubbles;
  for (const auto& b : iv) {
    if (b.fate == awcc::BubbleFate::paired) ++paired_complete;
  }
  EXPECT_EQ(z.count(awcc::ChordVelocity::bubble), paired_complete);
  EXPECT_GT(z.count(awcc::ChordVelocity::bubble), z.chords_given / 2);
  EXPECT_EQ(z.count(awcc::ChordVelocity::bubble) + z.count(awcc::ChordVelocity::window) +
                z.count(awcc::ChordVelocity::record) + z.count(awcc::ChordVelocity::none),
            z.chords_given);
  EXPECT_TRUE(z.velocity_note.empty()) << z.velocity_note;
}

TEST(PositionSizes, DualTipAreaIsFourFOverUAndSixCOverD32) {
  const auto r = process(lognormal_scene(0.3, 3), false);
  const auto& a = r.interfacial_area;
  ASSERT_TRUE(a.dual_tip);
  const auto& p = r.tips[0].phase;
  const double u = *r.velocity();
  EXPECT_DOUBLE_EQ(*a.dual_tip, 4.0 * p.bubble_count_rate / u);
  ASSERT_TRUE(p.sauter_diameter);
  EXPECT_NEAR(*a.dual_tip / (6.0 * p.void_fraction / *p.sauter_diameter), 1.0, 1e-14);
  EXPECT_EQ(a.source, awcc::AreaSource::dual_tip);
  EXPECT_FALSE(a.multi_tip);
  ASSERT_TRUE(a.dual_tip_ci95);
  EXPECT_LT(a.dual_tip_ci95->lower, *a.dual_tip);
  EXPECT_GT(a.dual_tip_ci95->upper, *a.dual_tip);
  // The sizes' 1.5 u c / F is the tip's, not a second formula's value.
  EXPECT_EQ(r.sizes->sauter_flux, p.sauter_diameter);
}

TEST(PositionSizes, AreaIntervalReducesToFsWhenTheVelocityIsExact) {
  // ln a = ln 4 + ln F - ln u: with u's interval of zero width, a's relative
  // interval is F's on each side; with F's of zero width, u's inverted.
  awcc::PhaseStatistics p;
  p.bubble_count_rate = 200.0;
  p.bubble_count_rate_ci95 = {180.0, 230.0};
  const auto a = awcc::interfacial_area(p, 2.0, awcc::Interval95{2.0, 2.0});
  ASSERT_TRUE(a.dual_tip_ci95);
  EXPECT_DOUBLE_EQ(*a.dual_tip, 400.0);
  EXPECT_NEAR(a.dual_tip_ci95->lower, 400.0 * 180.0 / 200.0, 1e-9);
  EXPECT_NEAR(a.dual_tip_ci95->upper, 400.0 * 230.0 / 200.0, 1e-9);
  p.bubble_count_rate_ci95 = {200.0, 200.0};
  const auto b = awcc::interfacial_area(p, 2.0, awcc::Interval95{1.6, 2.5});
  EXPECT_NEAR(b.dual_tip_ci95->lower, 4.0 * 200.0 / 2.5, 1e-9);
  EXPECT_NEAR(b.dual_tip_ci95->upper, 4.0 * 200.0 / 1.6, 1e-9);
  // No velocity: no value, and the reason says so.
  const auto c = awcc::interfacial_area(p, std::nullopt, std::nullopt);
  EXPECT_FALSE(c.value());
  EXPECT_NE(c.message.find("no velocity"), std::string::npos);
}

TEST(PositionSizes, NoVelocityGivesAStatusAndNoDistribution) {
  auto s = lognormal_scene(0.3, 5);
  s.duration = 2.0;
  const auto syn = synth::synthesise(s);
  awcc::PhaseStatistics p = awcc::phase_statistics(syn.signals[0]);
  const auto z = awcc::position_sizes(syn.signals[0], p, std::nullopt, std::nullopt, std::nullopt, "none");
  EXPECT_EQ(z.status, awcc::SizesStatus::no_velocity);
  EXPECT_FALSE(z.has_distribution());
  EXPECT_GT(z.chords_given, 0);
  EXPECT_EQ(z.count(awcc::ChordVelocity::none), z.chords_given);
}

TEST(PositionSizes, DropletsAreTheWaterChordsAndCoarseSamplingIsSaid) {
  // The complement of a bubbly signal is a spray of the same chords: its
  // water chords are the bubbly signal's air chords (between them).
  auto s = lognormal_scene(0.3, 9);
  s.duration = 5.0;
  const auto syn = synth::synthesise(s);
  awcc::AirIntervals spray;
  spray.fs = syn.signals[0].fs;
  spray.sample_count = syn.signals[0].sample_count;
  std::int64_t at = 0;
  for (const auto& iv : syn.signals[0].intervals) {
    if (iv.start > at) spray.intervals.push_back({at, iv.start});
    at = iv.stop;
  }
  if (at < spray.sample_count) spray.intervals.push_back({at, spray.sample_count});
  const auto p_bubbly = awcc::phase_statistics(syn.signals[0]);
  const auto p_spray = awcc::phase_statistics(spray);
  ASSERT_GT(p_spray.void_fraction, 0.7);
  const auto a = awcc::position_sizes(syn.signals[0], p_bubbly, std::nullopt, std::nullopt, 5.0, "fscc");
  const auto b = awcc::position_sizes(spray, p_spray, std::nullopt, std::nullopt, 5.0, "fscc");
  ASSERT_EQ(b.phase, awcc::DispersedPhase::droplets);
  ASSERT_TRUE(a.ok()) << a.message;
  ASSERT_TRUE(b.ok()) << b.message;
  EXPECT_EQ(a.distribution.median, b.distribution.median);
  EXPECT_EQ(a.distribution.d32, b.distribution.d32);
  // d32 of the droplets by the flux: 1.5 u (1 - c) / F of the spray.
  EXPECT_NEAR(*b.sauter_flux, 1.5 * 5.0 * (1.0 - p_spray.void_fraction) / p_spray.bubble_count_rate, 1e-15);

  // The median bubble (2 mm at 5 m/s, 100 kHz) spans 40 samples: asked for
  // more, no distribution is given, with the reason.
  EXPECT_NEAR(a.median_samples, a.distribution.median / (5.0 / 100e3), 1e-9 * a.median_samples);
  awcc::SizesOptions coarse;
  coarse.samples_min = a.median_samples * 1.01;
  const auto c = awcc::position_sizes(syn.signals[0], p_bubbly, std::nullopt, std::nullopt, 5.0, "fscc", coarse);
  EXPECT_EQ(c.status, awcc::SizesStatus::coarse_sampling);
  EXPECT_FALSE(c.has_distribution());
  EXPECT_NE(c.message.find("size-samples-min"), std::string::npos);
  EXPECT_EQ(c.median_samples, a.median_samples);
  EXPECT_EQ(c.distribution.mean_chord, a.distribution.mean_chord);
}

TEST(PositionSizes, JsonHoldsTheResultAndSizesOffLeavesItNull) {
  auto s = lognormal_scene(0.3, 13);
  s.duration = 10.0;
  const auto r = process(s, false);
  const json j = json::parse(awcc::to_json(r).dump());  // through text: what a reader sees
  const json& z = j.at(std::string(awcc::process_key::sizes));
  const auto& d = r.sizes->distribution;
  EXPECT_EQ(z.at("status"), "ok");
  EXPECT_EQ(z.at(std::string(awcc::process_key::dispersed_phase)), "bubbles");
  EXPECT_EQ(z.at(std::string(awcc::process_key::median)).get<double>(), d.median);
  EXPECT_EQ(z.at(std::string(awcc::process_key::d32)).get<double>(), d.d32);
  EXPECT_EQ(z.at(std::string(awcc::process_key::d10)).get<double>(), d.d10);
  EXPECT_EQ(z.at("chords_by_velocity").at("window").get<std::int64_t>(), r.sizes->count(awcc::ChordVelocity::window));
  const json& bins = z.at(std::string(awcc::process_key::bins));
  EXPECT_EQ(bins.at("diameters").get<std::vector<double>>(), d.diameters);
  EXPECT_EQ(bins.at("cumulative").get<std::vector<double>>(), d.cumulative);
  EXPECT_EQ(bins.at("edges").size(), d.diameters.size() + 1);
  const json& area = j.at(std::string(awcc::process_key::interfacial_area));
  EXPECT_EQ(area.at("value").get<double>(), *r.interfacial_area.dual_tip);
  EXPECT_EQ(area.at("source"), "dual_tip");
  EXPECT_TRUE(area.at("multi_tip").is_null());

  awcc::ProcessOptions o = awcc::process_options(std::vector<awcc::OptionSetting>{{"sizes", "off", "test"}});
  EXPECT_FALSE(o.sizes);
}

TEST(PositionSizes, AnOptionOutOfRangeIsRefusedByItsName) {
  for (const auto& [name, value] : {std::pair{"size-penalty", "0"}, std::pair{"size-bin-width", "2"},
                                    std::pair{"size-chords-min", "3"}, std::pair{"size-samples-min", "-1"},
                                    std::pair{"sizes", "maybe"}}) {
    try {
      (void)awcc::process_options(std::vector<awcc::OptionSetting>{{name, value, "test"}});
      ADD_FAILURE() << name << " = " << value << " was accepted";
    } catch (const awcc::OptionError& e) {
      EXPECT_NE(std::string(e.quantity()).find(name), std::string::npos) << e.what();
    }
  }
}

}  // namespace
