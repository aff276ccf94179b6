#include "synth/scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "awcc/errors.hpp"
#include "test_paths.hpp"

namespace {

using synth::Scene;

// The problems a validation reports, one per line.
std::vector<std::string> problems(const awcc::Validation& v) {
  std::vector<std::string> out;
  for (std::size_t at = 0; at < v.message.size();) {
    const auto end = std::min(v.message.find('\n', at), v.message.size());
    out.push_back(v.message.substr(at, end - at));
    at = end + 1;
  }
  return out;
}

// Expects exactly one problem, naming `field` (its quantity too when given) and containing `fragment`.
void expect_invalid(const Scene& s, const std::string& field, const std::string& fragment,
                    const std::string& quantity = {}) {
  const auto v = s.validate();
  ASSERT_EQ(v.status, awcc::ValidationStatus::invalid);
  const auto errors = problems(v);
  ASSERT_EQ(errors.size(), 1u) << v.message;
  EXPECT_NE(errors[0].find(field), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find(fragment), std::string::npos) << errors[0];
  if (!quantity.empty()) {
    EXPECT_EQ(v.quantity, quantity);
  }
}

TEST(Scene, DefaultsAreTheBaseCaseAndValid) {
  const Scene s;
  EXPECT_TRUE(s.validate().ok()) << s.validate().message;
  EXPECT_EQ(s.velocity, 10.0);
  EXPECT_EQ(s.tu, 0.25);
  EXPECT_EQ(s.tu_y, 0.125);
  EXPECT_EQ(s.time_scale, 0.1);
  EXPECT_EQ(s.rho_xz, -0.45);
  EXPECT_EQ(s.void_fraction, 0.25);
  EXPECT_EQ(s.bubble_diameter, 3e-3);
  EXPECT_EQ(s.dx, 5e-3);
  EXPECT_EQ(s.dy, 1e-3);
  EXPECT_EQ(s.fs, 500e3);
  EXPECT_EQ(s.duration, 300.0);
  EXPECT_EQ(s.sample_count(), 150'000'000);
  const auto tips = s.probe_tips();
  ASSERT_EQ(tips.size(), 2u);
  EXPECT_EQ(tips[1], (synth::Vec3{5e-3, 1e-3, 0.0}));
  // Automatic step: min(T/50 = 2 ms, |(5, 1) mm| / 10 m/s / 10 = 50.99 us),
  // shrunk to tile 300 s: 300 / ceil(300 / 50.99 us).
  const double nominal = std::hypot(5e-3, 1e-3) / 100.0;
  EXPECT_DOUBLE_EQ(s.effective_realisation_step(), 300.0 / std::ceil(300.0 / nominal));
}

TEST(Scene, ValidationNamesTheFieldAndTheRange) {
  Scene s;
  s.bubble_diameter = 0.0;
  expect_invalid(s, "bubble-diameter", "(0, 1 m]");
  s = Scene{};
  s.bubble_diameter = -2e-3;
  expect_invalid(s, "bubble-diameter", "-2mm");
  s = Scene{};
  s.void_fraction = 0.995;
  expect_invalid(s, "void-fraction", "(0, 0.99]");
  s = Scene{};
  s.void_fraction = 0.0;
  expect_invalid(s, "void-fraction", "(0, 0.99]");
  s = Scene{};
  s.fs = 0.0;
  expect_invalid(s, "fs", "> 0 Hz");
  s = Scene{};
  s.fs = -5.0;
  expect_invalid(s, "fs", "> 0 Hz");
  s = Scene{};
  s.duration = 1e-6;  // half a sample at 500 kHz
  expect_invalid(s, "duration", "shorter than one sample");
  s = Scene{};
  s.velocity = 0.0;
  expect_invalid(s, "velocity", "> 0 m/s", "velocity");
  s = Scene{};
  s.time_scale = -1.0;
  // time-scale-y and -z default to time-scale, so all three are reported,
  // and no single field is the fix.
  EXPECT_EQ(problems(s.validate()).size(), 3u) << s.validate().message;
  EXPECT_EQ(s.validate().quantity, "");
  const auto error = synth::invalid_scene(s.validate());
  EXPECT_EQ(std::string(error.what()).rfind("invalid scene:\n  time-scale = ", 0), 0u) << error.what();
  EXPECT_NE(std::string(error.what()).find("\n  time-scale-z = "), std::string::npos) << error.what();
  s = Scene{};
  s.tu = 1.5;
  expect_invalid(s, "tu", "[0, 1]");
  s = Scene{};
  s.rho_xz = 1.0;
  expect_invalid(s, "rho-xz", "(-1, 1)");
  s = Scene{};
  s.dx = 0.0;
  s.dy = 0.0;
  expect_invalid(s, "tips 0 and 1", "same point", "dx,dy,dz");
  s = Scene{};
  s.tips = {{0, 0, 0}, {1e-3, 0, 0}, {1e-3, 0, 0}, {0, 1e-3, 0}};
  expect_invalid(s, "tips 1 and 2", "same point", "tips");
  s = Scene{};
  s.aspect_ratio = 0.0;
  expect_invalid(s, "aspect-ratio", "[0.1, 10]");
}

TEST(Scene, CorrelationMatrixMustBePositiveDefinite) {
  // Each coefficient is in (-1, 1) but together they are impossible:
  // 1 + 2(0.9)(0.9)(-0.9) - 3(0.81) < 0.
  Scene s;
  s.rho_xy = 0.9;
  s.rho_xz = 0.9;
  s.rho_yz = -0.9;
  expect_invalid(s, "rho-xy", "not positive definite", "rho-xy,rho-xz,rho-yz");
}

TEST(Scene, EulerIsRefusedWhereItIsUnstable) {
  Scene s;
  s.velocity_update = synth::VelocityUpdate::euler;
  s.realisation_step = 0.25;  // dt/T = 2.5
  s.duration = 10.0;
  expect_invalid(s, "velocity-update", "euler is unstable", "velocity-update,realisation-step");
  s.velocity_update = synth::VelocityUpdate::exact;
  EXPECT_TRUE(s.validate().ok()) << s.validate().message;
}

TEST(SceneFields, NamesAreUniqueAndEveryFieldRoundTripsItsDefault) {
  std::set<std::string_view> names;
  Scene s;
  for (const auto& f : synth::scene_fields()) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    if (f.name == "tips" || f.name == "time-scale-y" || f.name == "time-scale-z") continue;
    Scene copy = s;
    f.parse(copy, f.format(s));  // the documented default parses back to itself
    EXPECT_EQ(f.format(copy), f.format(s)) << f.name;
  }
  for (const char* required : {"velocity", "tu", "tu-y", "tu-z", "time-scale", "rho-xz", "void-fraction",
                               "bubble-diameter", "dx", "dy", "dz", "fs", "duration", "seed"}) {
    EXPECT_TRUE(names.count(required)) << required;
  }
}

TEST(SceneFields, SetByNameWithUnits) {
  Scene s;
  synth::set_scene_field(s, "dx", "7.15mm");
  synth::set_scene_field(s, "fs", "20kHz");
  synth::set_scene_field(s, "duration", "45s");
  synth::set_scene_field(s, "arrival", "poisson-space");
  synth::set_scene_field(s, "tips", "0,0,0;5mm,0,0;0,2mm,0;0,0,2mm");
  EXPECT_DOUBLE_EQ(s.dx, 7.15e-3);
  EXPECT_DOUBLE_EQ(s.fs, 20e3);
  EXPECT_EQ(s.arrival, synth::ArrivalRule::poisson_space);
  ASSERT_EQ(s.probe_tips().size(), 4u);
  EXPECT_EQ(s.probe_tips()[3], (synth::Vec3{0, 0, 2e-3}));
  EXPECT_THROW(synth::set_scene_field(s, "dx", "7 kg"), std::invalid_argument);
  EXPECT_THROW(synth::set_scene_field(s, "no-such-field", "1"), std::invalid_argument);
  EXPECT_THROW(synth::set_scene_field(s, "arrival", "sometimes"), std::invalid_argument);
  EXPECT_THROW(synth::set_scene_field(s, "tips", "0,0;1,1"), std::invalid_argument);
  EXPECT_THROW(synth::set_scene_field(s, "seed", "1.5"), std::invalid_argument);
  // Sweep seeds use all 64 bits: a seed above 2^53 (where a double rounds
  // it) and the largest one replay exactly; one past it is refused.
  synth::set_scene_field(s, "seed", "6351225197166943491");
  EXPECT_EQ(s.seed, 6351225197166943491ULL);
  synth::set_scene_field(s, "seed", "18446744073709551615");
  EXPECT_EQ(s.seed, 18446744073709551615ULL);
  EXPECT_THROW(synth::set_scene_field(s, "seed", "18446744073709551616"), std::invalid_argument);
  EXPECT_THROW(synth::set_scene_field(s, "seed", "-3"), std::invalid_argument);
}

TEST(SceneToml, LoadsNumbersStringsWithUnitsAndTipArrays) {
  const auto path = pdp_test::temp_dir() / "scene_test.toml";
  {
    std::ofstream f(path);
    f << "velocity = \"5 m/s\"\n"
         "tu = 0.1\n"
         "bubble-diameter = \"2mm\"\n"
         "fs = \"100000Hz\"\n"
         "arrival = \"equal-space\"\n"
         "tips = [[0, 0, 0], [\"5mm\", \"0.5mm\", 0]]\n"  // zero needs no unit
         "seed = 42\n";
  }
  Scene s;
  synth::load_scene_toml(path, s);
  EXPECT_DOUBLE_EQ(s.velocity, 5.0);
  EXPECT_DOUBLE_EQ(s.tu, 0.1);
  EXPECT_DOUBLE_EQ(s.bubble_diameter, 2e-3);
  EXPECT_DOUBLE_EQ(s.fs, 1e5);
  EXPECT_EQ(s.arrival, synth::ArrivalRule::equal_space);
  EXPECT_EQ(s.seed, 42u);
  ASSERT_EQ(s.probe_tips().size(), 2u);
  EXPECT_DOUBLE_EQ(s.probe_tips()[1].y, 0.5e-3);
  EXPECT_EQ(s.tu_y, 0.125);  // untouched fields keep their values
}

TEST(SceneToml, ErrorsNameTheFileTheLineAndTheField) {
  const auto path = pdp_test::temp_dir() / "bad_scene.toml";
  {
    std::ofstream f(path);
    f << "velocity = 10\n"
         "bubble-diameter = \"3 kg\"\n";
  }
  Scene s;
  try {
    synth::load_scene_toml(path, s);
    FAIL() << "accepted 3 kg";
  } catch (const awcc::InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("bad_scene.toml:2"), std::string::npos) << m;
    EXPECT_NE(m.find("bubble-diameter"), std::string::npos) << m;
  }
  {
    std::ofstream f(path);
    f << "velocty = 10\n";
  }
  try {
    synth::load_scene_toml(path, s);
    FAIL() << "accepted an unknown key";
  } catch (const awcc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown scene field 'velocty'"), std::string::npos) << e.what();
  }
  {
    std::ofstream f(path);
    f << "velocity = = 10\n";
  }
  EXPECT_THROW(synth::load_scene_toml(path, s), awcc::InputError);
}

TEST(SceneToml, ShippedSamplesLoadAndValidate) {
  for (const char* name : {"base.toml", "high-tu.toml", "small-bubbles.toml", "low-void-fraction.toml",
                           "short-time-scale.toml", "four-tip.toml"}) {
    Scene s;
    ASSERT_NO_THROW(synth::load_scene_toml(pdp_test::source_dir() / "samples" / name, s)) << name;
    EXPECT_TRUE(s.validate().ok()) << name << ": " << s.validate().message;
  }
}

}  // namespace
