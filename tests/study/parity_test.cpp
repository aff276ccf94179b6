// The studies process a synthesised record as pdp process processes the
// recording libsynth writes of it. The correction's features of one scene,
// made three ways, are identical field by field: as a sweep row (the
// library's sweep row code), as pdp process makes them of the file
// (awcc::process_recording, then correction::measurement_of, as --correct
// does), and from pdp process's JSON read back by pdp correct's reader
// (correction::measurement_of_json). The scenes have explicit tips (the
// pair processed is the first two of three), and one runs with the
// bubble-probe correction on (the probe-corrected rule).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "../awcc/clean_scene.hpp"
#include "awcc/csv.hpp"
#include "awcc/json_text.hpp"
#include "awcc/process.hpp"
#include "awcc/serialise.hpp"
#include "correction/rows.hpp"
#include "correction/training.hpp"
#include "study/sweep.hpp"
#include "synth/recording.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

using correction::FeatureResult;
using correction::MeasurementResult;

// A short record of a three-tip probe given by explicit tips: the first two
// are the pair; the lateral separation has y and z parts (hypot(dy, dz)).
synth::Scene three_tips(std::uint64_t seed) {
  synth::Scene s;
  s.velocity = 2.0;
  s.tu = 0.1;
  s.tu_y = s.tu_z = 0.05;
  s.void_fraction = 0.15;
  s.bubble_diameter = 2e-3;
  s.time_scale = 20e-3;
  s.fs = 100e3;
  s.duration = 8.0;
  s.seed = seed;
  s.tips = {{0.0, 0.0, 0.0}, {4e-3, 0.3e-3, 0.4e-3}, {9e-3, -1e-3, 0.0}};
  return s;
}

struct Paths {
  MeasurementResult sweep, process, json;
  std::string sweep_row;
  awcc::ProcessResult processed;  ///< pdp process's result
};

// The scene as a sweep row, and as pdp process and pdp correct see its file.
Paths three_ways(const synth::Scene& scene, const study::RunOptions& options, const std::string& name) {
  Paths out;
  study::SweepRun run;
  run.index = 3;
  run.scene = scene;
  run.np = options.awcc.np;
  const auto r = study::run_scene(scene, options);
  out.sweep = r.measurement;
  out.sweep_row = study::run_sweep_row(run, options, 77);

  const auto file = pdp_test::test_file(name + ".flac");
  const auto syn = synth::synthesise(scene);
  synth::write_recording(file, scene, syn.signals);
  // pdp process --dx --dy --np (and --probe-correction): its defaults otherwise.
  awcc::ProcessOptions p;
  p.dx = scene.streamwise_separation();
  p.dy = scene.lateral_separation();
  p.awcc_options = options.awcc;
  p.fscc_options = options.fscc;
  out.processed = awcc::process_recording(file, p);
  out.process = correction::measurement_of(out.processed);
  const auto text = awcc::json_text(awcc::to_json(out.processed));
  out.json = correction::measurement_of_json(nlohmann::json::parse(text), {}, name + ".json");
  return out;
}

void expect_identical(const MeasurementResult& a, const MeasurementResult& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.message, b.message);
  const auto& x = a.measurement;
  const auto& y = b.measurement;
  EXPECT_EQ(x.velocity, y.velocity);
  EXPECT_EQ(x.turbulence_intensity, y.turbulence_intensity);
  EXPECT_EQ(x.void_fraction, y.void_fraction);
  EXPECT_EQ(x.bubble_count_rate, y.bubble_count_rate);
  EXPECT_EQ(x.d32, y.d32);
  EXPECT_EQ(x.dx, y.dx);
  EXPECT_EQ(x.dy, y.dy);
  EXPECT_EQ(x.np, y.np);
  EXPECT_EQ(x.windows_accepted, y.windows_accepted);
  EXPECT_EQ(x.windows_total, y.windows_total);
  EXPECT_EQ(x.fs, y.fs);
  EXPECT_EQ(x.duration, y.duration);
  EXPECT_EQ(x.fscc_velocity, y.fscc_velocity);
  EXPECT_EQ(x.r12_max, y.r12_max);
  // The features, by the one contract.
  const FeatureResult f = correction::make_features(x), g = correction::make_features(y);
  EXPECT_EQ(f.status, g.status);
  for (const auto& names : {correction::feature_set_names("extended"), correction::feature_set_names("extended-yield"),
                            correction::feature_set_names("fscc")}) {
    for (const auto& n : names) EXPECT_EQ(f.features.value(n), g.features.value(n)) << n;
  }
}

// The sweep row's cells that the correction's training reads, read back by
// it: the same features to the CSV's ten significant digits. A row without
// AWCC's features is left out of training as one without its velocity.
void expect_row_trains_as(const std::string& row, const FeatureResult& f, const std::string& name) {
  const auto csv = pdp_test::test_file(name + ".csv");
  std::ofstream(csv) << study::sweep_header() << "\n" << row;
  if (!f.ok()) {
    try {
      (void)correction::load_training_set({csv}, 0);
      ADD_FAILURE() << "a row without AWCC's features was taken for training";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("1 without an AWCC velocity"), std::string::npos) << e.what();
    }
    return;
  }
  const auto set = correction::load_training_set({csv}, 0);
  ASSERT_EQ(set.rows.size(), 1u);
  ASSERT_EQ(set.fscc_rows.size(), 1u);
  for (const auto& [features, names] : {std::pair{&set.rows[0].features, correction::feature_set_names("extended-yield")},
                                        std::pair{&set.fscc_rows[0].features, correction::feature_set_names("fscc")}}) {
    for (const auto& n : names) {
      const auto want = f.features.value(n);
      const auto got = features->value(n);
      ASSERT_TRUE(want && got) << n;
      EXPECT_NEAR(*got, *want, 1e-9 * std::fabs(*want)) << n;
    }
  }
}

TEST(Parity, ASweepRowMeasuresWhatPdpProcessAndPdpCorrectMeasure) {
  const auto scene = three_tips(11);
  study::RunOptions options;
  options.awcc.np = 8;
  const auto paths = three_ways(scene, options, "plain");
  // A row the correction takes: AWCC gave a velocity, FSCC too.
  ASSERT_EQ(paths.process.status, correction::CorrectionStatus::corrected) << paths.process.message;
  ASSERT_TRUE(paths.process.measurement.fscc_velocity);
  EXPECT_EQ(paths.process.measurement.np, 8);
  EXPECT_EQ(paths.process.measurement.dx, 4e-3);
  EXPECT_EQ(paths.process.measurement.dy, std::hypot(0.3e-3, 0.4e-3));
  expect_identical(paths.sweep, paths.process, "sweep row against pdp process");
  expect_identical(paths.json, paths.process, "pdp process's JSON against its result");
  expect_row_trains_as(paths.sweep_row, correction::make_features(paths.process.measurement), "plain");
}

TEST(Parity, TheProbeCorrectedRuleIsTheProcessingPaths) {
  const auto scene = three_tips(12);
  study::RunOptions options;
  options.awcc.probe_correction.enabled = true;
  options.awcc.probe_correction.needle_diameter = 0.8e-3;
  const auto paths = three_ways(scene, options, "probe");
  // AWCC gave a corrected velocity, which the correction does not take; FSCC's it may.
  ASSERT_TRUE(paths.processed.awcc && paths.processed.awcc->ok() && paths.processed.awcc->probe_corrected);
  ASSERT_EQ(paths.process.status, correction::CorrectionStatus::probe_corrected);
  EXPECT_FALSE(paths.process.measurement.velocity);
  ASSERT_TRUE(paths.process.measurement.fscc_velocity);
  expect_identical(paths.sweep, paths.process, "sweep row against pdp process");
  expect_identical(paths.json, paths.process, "pdp process's JSON against its result");
  // The row carries no AWCC velocity for training, and says why.
  EXPECT_NE(paths.sweep_row.find("bubble-probe corrected"), std::string::npos) << paths.sweep_row;
  expect_row_trains_as(paths.sweep_row, correction::make_features(paths.process.measurement), "probe");
}

TEST(Parity, AStudysD32IsPdpProcesss) {
  // pdp process's d32 comes from the velocity METHOD 4 item 10 chooses; a
  // study reports it under that method, and none under the other.
  const auto scene = three_tips(13);
  const auto r = study::run_scene(scene, {});
  const auto& p = r.processed;
  const auto source = p.velocity_source();
  ASSERT_NE(source, awcc::VelocitySource::none);
  const auto& reported = source == awcc::VelocitySource::awcc ? r.awcc_d32 : r.fscc_d32;
  const auto& other = source == awcc::VelocitySource::awcc ? r.fscc_d32 : r.awcc_d32;
  ASSERT_TRUE(reported.value);
  EXPECT_EQ(*reported.value, *p.tips[0].phase.sauter_diameter);
  EXPECT_EQ(*reported.value, 1.5 * *p.velocity() * p.tips[0].phase.void_fraction / p.tips[0].phase.bubble_count_rate);
  EXPECT_FALSE(other.value);
}

}  // namespace

namespace {

// A four-tip probe, processed bubble by bubble: the sweep row's multi-tip
// cells, pdp process of the written file (its tips declared, as a lab
// declares them for a FLAC) and the JSON of that result say the same mean
// vector, Tu per component and interfacial area, to the row's ten digits.
TEST(Parity, AFourTipSweepRowIsPdpProcessOfItsFileAndItsJson) {
  study::SweepRun run;
  run.index = 5;
  run.np = 10;
  run.scene = pdp_test::clean_four_tip_scene(12.0);
  study::RunOptions options;
  options.awcc.np = run.np;
  const auto r = study::run_scene(run.scene, options);
  ASSERT_TRUE(r.processed.probe);
  const auto row = study::run_sweep_row(run, options, 78);

  const auto file = pdp_test::test_file("four-tip.flac");
  const auto syn = synth::synthesise(run.scene);
  synth::write_recording(file, run.scene, syn.signals);
  awcc::ProcessOptions p;
  for (const auto& t : run.scene.probe_tips()) p.probe.positions.push_back({t.x, t.y, t.z});
  p.awcc_options = options.awcc;
  p.fscc_options = options.fscc;
  const auto processed = awcc::process_recording(file, p);
  ASSERT_TRUE(processed.probe);
  const auto& a = r.processed.probe->vectors;
  const auto& b = processed.probe->vectors;
  ASSERT_TRUE(a.ok() && b.ok()) << a.message << b.message;
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_EQ(a.velocity[j], b.velocity[j]) << j;
    EXPECT_EQ(a.turbulence_intensity[j], b.turbulence_intensity[j]) << j;
  }
  EXPECT_EQ(a.interfacial_area, b.interfacial_area);
  EXPECT_EQ(a.bubbles_accepted, b.bubbles_accepted);
  EXPECT_EQ(r.processed.probe->quality, processed.probe->quality);
  // The row holds them as written ({:.10g}).
  const auto cells = awcc::split_cells(row);
  const auto names = awcc::split_cells(study::sweep_header());
  auto cell = [&](const std::string& name) {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == name) return cells.at(i);
    ADD_FAILURE() << "no column " << name;
    return std::string();
  };
  EXPECT_EQ(cell("multi_tip_velocity_x"), fmt::format("{:.10g}", b.velocity[0]));
  EXPECT_EQ(cell("multi_tip_velocity_z"), fmt::format("{:.10g}", b.velocity[2]));
  EXPECT_EQ(cell("multi_tip_turbulence_intensity_y"), fmt::format("{:.10g}", b.turbulence_intensity[1]));
  EXPECT_EQ(cell("multi_tip_interfacial_area"), fmt::format("{:.10g}", *b.interfacial_area));
  // And the JSON of pdp process's result, read back.
  const auto j = nlohmann::json::parse(awcc::json_text(awcc::to_json(processed)));
  const auto& m = j.at("multi_tip");
  EXPECT_EQ(m.at("velocity").at(0).get<double>(), b.velocity[0]);
  EXPECT_EQ(m.at("velocity").at(1).get<double>(), b.velocity[1]);
  EXPECT_EQ(m.at("turbulence_intensity").at(2).get<double>(), b.turbulence_intensity[2]);
  // The pair's measurement too, as in the three-tip scenes.
  expect_identical(r.measurement, correction::measurement_of(processed), "four tips: sweep against pdp process");
}

}  // namespace
