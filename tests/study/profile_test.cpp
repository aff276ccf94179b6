// The synthetic profile (study/profile.hpp): its laws, its truth by
// quadrature against closed forms and exact identities, its settings file,
// and the refusals at the limits of its fields.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "awcc/errors.hpp"
#include "awcc/random.hpp"
#include "study/profile.hpp"
#include "test_paths.hpp"

namespace {

using awcc::ConcentrationModelKind;

study::ProfileSpec spec_of(ConcentrationModelKind kind, double d) {
  study::ProfileSpec s;
  s.model = kind;
  s.diffusivity = d;
  s.y90 = 0.05;
  s.u90 = 5.0;
  s.power_law_n = 6.0;
  s.positions = {0.005, 0.01, 0.02};
  return s;
}

TEST(ProfileTruth, SmoothChuteMeanConcentrationEqualsItsClosedForm) {
  // Chanson (1997): C_mean = 2 D' (tanh K' - sqrt(0.1)), K' = atanh(sqrt(0.1))
  // + 1 / (2 D'), the integral of sech^2 over [0, 1] in y': an independent
  // check of the quadrature and of the law below Y90.
  for (const double d : {0.1, 0.3, 1.0}) {
    const auto spec = spec_of(ConcentrationModelKind::smooth_chute, d);
    const auto t = study::profile_truth(spec, std::vector<double>{});
    const double k = std::atanh(std::sqrt(0.1)) + 1.0 / (2 * d);
    const double closed = 2 * d * (std::tanh(k) - std::sqrt(0.1));
    EXPECT_NEAR(t.c_mean, closed, 1e-10 * closed) << "D' = " << d;
    EXPECT_NEAR(t.clear_water_depth, (1 - closed) * spec.y90, 1e-12);
  }
}

TEST(ProfileTruth, DischargesAddUpToTheIntegralOfThePowerLaw) {
  // q_w + q_a = int_0^Y90 u dy = u90 Y90 N / (N + 1) exactly, whatever c.
  for (const auto kind : {ConcentrationModelKind::smooth_chute, ConcentrationModelKind::stepped_chute}) {
    for (const double n : {2.0, 6.0, 10.0}) {
      auto spec = spec_of(kind, 0.25);
      spec.power_law_n = n;
      const auto t = study::profile_truth(spec, std::vector<double>{});
      const double total = spec.u90 * spec.y90 * n / (n + 1);
      EXPECT_NEAR(t.water_discharge + t.air_discharge, total, 1e-10 * total) << "N = " << n;
      EXPECT_GT(t.air_discharge, 0.0);
      // Air moves faster than average (c rises with y as u does): q_a / q > C_mean.
      EXPECT_GT(t.air_discharge / total, t.c_mean);
    }
  }
}

TEST(ProfileTruth, CharacteristicDepthsAreTheLawsCrossings) {
  const auto spec = spec_of(ConcentrationModelKind::stepped_chute, 0.2);
  const std::vector<double> levels{0.03, 0.5, 0.9, 0.95};
  const auto t = study::profile_truth(spec, levels);
  ASSERT_EQ(t.depths.size(), 4u);
  EXPECT_FALSE(t.depths[0]) << "c(0) = 0.042 exceeds 0.03: the crossing lies below the invert";
  for (std::size_t i = 1; i < levels.size(); ++i) {
    ASSERT_TRUE(t.depths[i]);
    EXPECT_NEAR(study::profile_void_fraction(spec, *t.depths[i]), levels[i], 1e-12);
  }
  EXPECT_NEAR(*t.depths[2], spec.y90, 1e-12);
  // Above Y90 the continuation: 1 - 0.1 exp(-(y - Y90) s / 0.1), so Y95 =
  // Y90 + 0.1 ln 2 / s.
  const double h = 1e-6 * spec.y90;
  const double s = (study::profile_void_fraction(spec, spec.y90) - study::profile_void_fraction(spec, spec.y90 - h)) / h;
  EXPECT_NEAR(*t.depths[3], spec.y90 + 0.1 * std::log(2.0) / s, 1e-4 * spec.y90);
}

TEST(ProfileLaws, ContinuousWithItsSlopeAtY90AndRisingToOne) {
  for (const auto kind : {ConcentrationModelKind::smooth_chute, ConcentrationModelKind::stepped_chute}) {
    const auto spec = spec_of(kind, 0.2);
    const double y = spec.y90, h = 1e-7 * y;
    const double below = (study::profile_void_fraction(spec, y) - study::profile_void_fraction(spec, y - h)) / h;
    const double above = (study::profile_void_fraction(spec, y + h) - study::profile_void_fraction(spec, y)) / h;
    EXPECT_NEAR(study::profile_void_fraction(spec, y), 0.9, 1e-12);
    EXPECT_NEAR(above, below, 1e-3 * below);
    double previous = 0.0;
    for (double yp = 0.0; yp <= 6.0; yp += 0.01) {
      const double c = study::profile_void_fraction(spec, yp * y);
      EXPECT_GE(c, previous) << "y' = " << yp;
      previous = c;
    }
    EXPECT_GT(previous, 0.999);
  }
}

TEST(ProfileScene, EachPositionTakesTheLawsAndADerivedSeed) {
  auto spec = spec_of(ConcentrationModelKind::stepped_chute, 0.2);
  spec.tu_invert = 0.3;
  spec.tu_y90 = 0.1;
  spec.bubble_diameter_invert = 4e-3;
  spec.bubble_diameter_y90 = 2e-3;
  spec.scene.tu = 0.2;
  spec.scene.tu_y = 0.1;
  spec.scene.tu_z = 0.05;
  spec.positions = {0.0125, 0.075};
  const auto a = study::position_scene(spec, 0);
  EXPECT_DOUBLE_EQ(a.velocity, 5.0 * std::pow(0.25, 1.0 / 6.0));
  EXPECT_DOUBLE_EQ(a.tu, 0.25);
  EXPECT_DOUBLE_EQ(a.tu_y, 0.125);
  EXPECT_DOUBLE_EQ(a.tu_z, 0.0625);
  EXPECT_DOUBLE_EQ(a.bubble_diameter, 3.5e-3);
  EXPECT_DOUBLE_EQ(a.void_fraction, study::profile_void_fraction(spec, 0.0125));
  EXPECT_EQ(a.seed, awcc::derive_seed(spec.scene.seed, 0));
  const auto b = study::position_scene(spec, 1);  // above Y90: Tu and d_b held at Y90's
  EXPECT_DOUBLE_EQ(b.tu, 0.1);
  EXPECT_DOUBLE_EQ(b.bubble_diameter, 2e-3);
  EXPECT_EQ(b.seed, awcc::derive_seed(spec.scene.seed, 1));
}

TEST(ProfileSpec, RefusesEachFieldAtItsLimit) {
  auto ok = spec_of(ConcentrationModelKind::smooth_chute, 0.3);
  EXPECT_TRUE(ok.validate().ok()) << ok.validate().message;
  auto s = ok;
  s.positions = {0.01};
  EXPECT_EQ(s.validate().quantity, "positions");
  s = ok;
  s.positions = {0.01, 0.01};
  EXPECT_EQ(s.validate().quantity, "positions");
  s = ok;
  s.positions = {0.02, 0.01};
  EXPECT_EQ(s.validate().quantity, "positions");
  s = ok;
  s.positions = {0.0, 0.01};
  EXPECT_EQ(s.validate().quantity, "positions");
  s = ok;
  s.power_law_n = 0.99;
  EXPECT_EQ(s.validate().quantity, "power-law-n");
  s.power_law_n = 1.0;
  EXPECT_TRUE(s.validate().ok());
  s = ok;
  s.tu_y90 = 0.36;
  EXPECT_EQ(s.validate().quantity, "tu-y90");
  s = ok;
  s.diffusivity = 0.009;
  EXPECT_EQ(s.validate().quantity, "diffusivity");
}

TEST(ProfileFile, TheSampleReadsAndALawFieldInSceneIsRefused) {
  const auto spec = study::load_profile_spec(pdp_test::source_dir() / "samples/stepped-profile.toml");
  EXPECT_EQ(spec.model, ConcentrationModelKind::stepped_chute);
  EXPECT_DOUBLE_EQ(spec.y90, 0.05);
  EXPECT_EQ(spec.positions.size(), 24u);
  EXPECT_DOUBLE_EQ(spec.scene.fs, 100e3);
  EXPECT_EQ(spec.scene.arrival, synth::ArrivalRule::equal_space);

  const auto path = pdp_test::test_file("profile.toml");
  {
    std::ofstream out(path);
    out << "[profile]\ny90 = \"50mm\"\npositions = \"5mm,10mm\"\n[scene]\nvelocity = \"3m/s\"\n";
  }
  try {
    study::load_profile_spec(path);
    FAIL() << "a law's field in [scene] was read";
  } catch (const awcc::InputError& e) {
    EXPECT_EQ(e.quantity(), "velocity");
    EXPECT_NE(std::string(e.what()).find(":5:"), std::string::npos) << e.what();
  }
  {
    std::ofstream out(path);
    out << "[profile]\ny90 = 50\n";
  }
  EXPECT_THROW(study::load_profile_spec(path), awcc::InputError) << "a length without its unit";
  {
    std::ofstream out(path);
    out << "[profile]\ny-ninety = \"50mm\"\n";
  }
  try {
    study::load_profile_spec(path);
    FAIL() << "an unknown field was read";
  } catch (const awcc::InputError& e) {
    EXPECT_EQ(e.quantity(), "y-ninety");
  }
}

}  // namespace
