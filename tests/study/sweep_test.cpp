// Sweep rows and the task engine of the study library.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <fmt/format.h>
#include <sstream>

#include "awcc/clean_scene.hpp"
#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "correction/sweep_columns.hpp"
#include "correction/training.hpp"
#include "study/sweep.hpp"
#include "study/tasks.hpp"
#include "test_paths.hpp"

namespace {

std::vector<std::string> cells_of(std::string line) {
  if (!line.empty() && line.back() == '\n') line.pop_back();
  return awcc::split_cells(line);
}

std::string cell(const std::string& row, const std::string& column) {
  const auto header = cells_of(study::sweep_header());
  const auto cells = cells_of(row);
  const auto at = std::find(header.begin(), header.end(), column) - header.begin();
  return cells.at(static_cast<std::size_t>(at));
}

// A short run with enough bubbles for AWCC windows.
study::SweepRun short_run() {
  study::SweepRun run;
  run.np = 6;
  run.scene.fs = 50e3;
  run.scene.duration = 2.0;
  run.scene.dx = 3e-3;
  run.scene.dy = 0.5e-3;
  run.scene.seed = 21;
  return run;
}

TEST(SweepRows, AFailedRunIsAFullRowWithItsReason) {
  study::SweepRun run;
  run.index = 4;
  run.scene.tips = {{0.0, 0.0, 0.0}};  // one tip: nothing to correlate
  const auto row = study::run_sweep_row(run, {}, 9);
  EXPECT_EQ(cells_of(row).size(), cells_of(study::sweep_header()).size());
  EXPECT_EQ(cell(row, "truth_velocity"), "");
  EXPECT_NE(cell(row, "reason").find("FSCC and AWCC need two"), std::string::npos) << row;
  EXPECT_EQ(cell(row, "run"), "4");
}

TEST(SweepRows, TheCorrectionsCellsAreTheRunsMeasurement) {
  const auto run = short_run();
  study::RunOptions options;
  options.awcc.np = run.np;
  const auto r = study::run_scene(run.scene, options);
  const auto& m = r.measurement.measurement;
  const auto row = study::sweep_row(run, &r, "", 1, options.awcc);
  ASSERT_TRUE(m.velocity && m.fscc_velocity);
  EXPECT_EQ(cell(row, "awcc_velocity"), fmt::format("{:.10g}", *m.velocity));
  EXPECT_EQ(cell(row, "awcc_turbulence_intensity"), fmt::format("{:.10g}", *m.turbulence_intensity));
  EXPECT_EQ(cell(row, "awcc_void_fraction"), fmt::format("{:.10g}", m.void_fraction));
  EXPECT_EQ(cell(row, "awcc_count_rate"), fmt::format("{:.10g}", m.bubble_count_rate));
  EXPECT_EQ(cell(row, "awcc_windows_accepted"), std::to_string(m.windows_accepted));
  EXPECT_EQ(cell(row, "awcc_windows_total"), std::to_string(m.windows_total));
  EXPECT_EQ(cell(row, "fscc_velocity"), fmt::format("{:.10g}", *m.fscc_velocity));
  EXPECT_EQ(cell(row, "probe_dx"), "0.003");
  EXPECT_EQ(cell(row, "probe_dy"), "0.0005");
  EXPECT_EQ(cell(row, "np"), "6");
  // The run's processing: pdp process's, the leading tip's phase statistics included.
  EXPECT_EQ(m.void_fraction, r.processed.tips[0].phase.void_fraction);
  EXPECT_EQ(m.windows_accepted, r.processed.awcc->windows_accepted);
  // Both methods run together: no time of their own.
  EXPECT_EQ(cell(row, "seconds_fscc"), "");
  EXPECT_EQ(cell(row, "seconds_awcc"), "");
}

// The unweighted moments a duration-weighted run writes beside its own are
// AWCC's with weighting none, to the last digit: the same windows, the other
// convention; a run processed unweighted leaves them empty.
TEST(SweepRows, TheUnweightedMomentsAreAwccsWithWeightingNone) {
  auto run = short_run();
  run.scene.arrival = synth::ArrivalRule::poisson_space;  // the weighting then matters
  run.scene.duration = 6.0;
  study::RunOptions options;
  options.awcc.np = run.np;
  const auto weighted = study::run_scene(run.scene, options);
  const auto row = study::sweep_row(run, &weighted, "", 1, options.awcc);
  auto unweighted_options = options;
  unweighted_options.awcc.weighting = awcc::Weighting::none;
  const auto unweighted = study::run_scene(run.scene, unweighted_options);
  const auto& m = unweighted.measurement.measurement;
  ASSERT_TRUE(m.velocity && weighted.measurement.measurement.velocity);
  EXPECT_EQ(cell(row, "awcc_velocity_unweighted"), fmt::format("{:.10g}", *m.velocity));
  EXPECT_EQ(cell(row, "awcc_turbulence_intensity_unweighted"), fmt::format("{:.10g}", *m.turbulence_intensity));
  EXPECT_NE(cell(row, "awcc_velocity_unweighted"), cell(row, "awcc_velocity"));
  const auto plain = study::sweep_row(run, &unweighted, "", 1, unweighted_options.awcc);
  EXPECT_EQ(cell(plain, "awcc_velocity_unweighted"), "");
  EXPECT_EQ(cell(plain, "awcc_turbulence_intensity_unweighted"), "");
}

// A four-tip scene (the clean one of METHOD 11.7: 8 mm spheres, Tu 0.05,
// tips 2 mm apart) is processed bubble by bubble in a sweep, as pdp process
// processes a recording stating its tips: the row carries the mean vector,
// Tu per component and the interfacial area beside their truths; a dual-tip
// run leaves those cells empty and still gives the lateral truths.
TEST(SweepRows, AFourTipSceneCarriesTheMultiTipVectorBesideItsTruth) {
  study::SweepRun run;
  run.np = 10;
  run.scene = pdp_test::clean_four_tip_scene(30.0);
  study::RunOptions options;
  options.awcc.np = run.np;
  const auto r = study::run_scene(run.scene, options);
  ASSERT_TRUE(r.processed.probe);
  const auto& v = r.processed.probe->vectors;
  ASSERT_TRUE(v.ok()) << v.message;
  EXPECT_EQ(r.processed.probe->channels, (std::vector<int>{0, 1, 2, 3}));
  const auto row = study::sweep_row(run, &r, "", 1, options.awcc);
  EXPECT_EQ(cell(row, "multi_tip_velocity_x"), fmt::format("{:.10g}", v.velocity[0]));
  EXPECT_EQ(cell(row, "multi_tip_turbulence_intensity_z"), fmt::format("{:.10g}", v.turbulence_intensity[2]));
  EXPECT_EQ(cell(row, "multi_tip_interfacial_area"), fmt::format("{:.10g}", *v.interfacial_area));
  EXPECT_EQ(cell(row, "multi_tip_bubbles_accepted"), std::to_string(v.bubbles_accepted));
  EXPECT_EQ(cell(row, "multi_tip_quality"), std::string(awcc::to_string(r.processed.probe->quality)));
  EXPECT_EQ(cell(row, "truth_interfacial_area"), fmt::format("{:.10g}", 6 * 0.05 / 8e-3));
  EXPECT_EQ(cell(row, "truth_velocity_y"), fmt::format("{:.10g}", r.multi_tip_velocity[1].truth));
  // The estimate against its truth: some 300 accepted bubbles of speed
  // spread Tu = 0.05 give the mean's sampling sd 0.05 / sqrt(300) = 0.3 %;
  // the per-bubble timing error (one 5 us sample in a 1 ms lag, 0.5 %) adds
  // 0.5 % / sqrt(300). 2 % is beyond 5 sd of both.
  ASSERT_TRUE(r.multi_tip_velocity[0].error());
  EXPECT_LT(std::fabs(*r.multi_tip_velocity[0].error()), 0.02);
  // The interfacial area (4/T) N_0 <1/|v|>: N_0 of about 500 complete
  // bubbles, a Poisson sd of 4.5 %; 20 % is beyond 4 sd.
  ASSERT_TRUE(r.multi_tip_interfacial_area.error());
  EXPECT_LT(std::fabs(*r.multi_tip_interfacial_area.error()), 0.2);
  // A dual-tip run: no multi-tip cells.
  const auto pair = short_run();
  const auto rp = study::run_scene(pair.scene, options);
  const auto pair_row = study::sweep_row(pair, &rp, "", 1, options.awcc);
  EXPECT_EQ(cell(pair_row, "multi_tip_velocity_x"), "");
  EXPECT_EQ(cell(pair_row, "multi_tip_quality"), "");
}

// The writer's header is the declaration (key columns, the scene's fields,
// the result columns in order); what the writer puts in a row, training reads
// back: the correction's features and the processing, every value of them.
TEST(SweepRows, WhatTheWriterWritesTrainingReadsBack) {
  const auto header = cells_of(study::sweep_header());
  std::vector<std::string> declared;
  for (const auto& c : correction::sweep_key_columns) declared.emplace_back(c.name);
  const auto scene = header.size() - correction::sweep_key_columns.size() - correction::sweep_result_column_count;
  declared.insert(declared.end(), header.begin() + 3, header.begin() + 3 + static_cast<std::ptrdiff_t>(scene));
  for (const auto& c : correction::sweep_result_columns) declared.emplace_back(c.name);
  EXPECT_EQ(header, declared);
  EXPECT_EQ(std::set<std::string>(header.begin(), header.end()).size(), header.size()) << "a column twice";

  const auto run = short_run();
  study::RunOptions options;
  options.awcc.np = run.np;
  // Every processing column away from its default, so that a default read is caught.
  options.awcc.filter_a = 0.3;
  options.awcc.roc = false;
  options.awcc.weighting = awcc::Weighting::none;
  options.awcc.subsample = awcc::Subsample::parabolic;
  const auto r = study::run_scene(run.scene, options);
  const auto row = study::sweep_row(run, &r, "", 7, options.awcc);
  ASSERT_EQ(cells_of(row).size(), header.size()) << row;
  study::SweepRun failed = run;
  failed.index = 1;
  ASSERT_EQ(cells_of(study::sweep_row(failed, nullptr, "boom", 7, options.awcc)).size(), header.size());
  EXPECT_EQ(cell(row, "awcc_signal"), "binary");
  EXPECT_EQ(cell(row, "awcc_weighting"), "none");

  const auto file = pdp_test::temp_dir() / "sweep_round_trip.csv";
  std::ofstream(file) << study::sweep_header() << "\n" << row << "\n" << study::sweep_row(failed, nullptr, "boom", 7, options.awcc) << "\n";
  const auto set = correction::load_training_set({file}, 1);
  EXPECT_EQ(set.total, 2);
  EXPECT_EQ(set.excluded_error, 1);
  ASSERT_EQ(set.rows.size(), 1u);
  EXPECT_FALSE(set.processing_assumed);
  EXPECT_TRUE(set.processing == correction::processing_of(options.awcc)) << correction::describe(set.processing);
  const auto& read = set.rows[0];
  EXPECT_EQ(read.study, 7u);
  EXPECT_EQ(read.run, 0);
  // The cells carry 10 significant digits: the features agree to that.
  const auto expected = correction::make_features(r.measurement.measurement).features;
  for (const auto& name : correction::feature_set_names("extended")) {
    const auto a = read.features.value(name), b = expected.value(name);
    ASSERT_TRUE(a && b) << name;
    EXPECT_NEAR(*a, *b, 1e-9 * std::max(1.0, std::fabs(*b))) << name;
  }
  EXPECT_NEAR(read.true_velocity, r.truth_velocity, 1e-9 * r.truth_velocity);
  EXPECT_NEAR(read.true_turbulence_intensity, r.truth_turbulence_intensity, 1e-9);
}

TEST(Tasks, EveryTaskIsAppendedOnceWhateverTheThreads) {
  std::vector<std::int64_t> tasks;
  for (std::int64_t t = 0; t < 40; ++t) tasks.push_back(3 * t);
  auto text = [](std::int64_t t) { return fmt::format("{},{}\n{},{}\n", t, t * t, t, -t); };
  for (int threads : {1, 3}) {
    const auto file = pdp_test::test_file(fmt::format("tasks{}.csv", threads));
    std::ofstream(file) << "head\n";
    double last = 0.0;
    int calls = 0;
    study::run_tasks(tasks, text, file.string(), threads, [&](double f) {
      EXPECT_GE(f, last);
      last = f;
      ++calls;
    });
    EXPECT_EQ(calls, 40);
    EXPECT_EQ(last, 1.0);
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "head");
    std::multiset<std::string> seen;
    // A task's two lines stay together (one write per task).
    while (std::getline(in, line)) {
      std::string second;
      ASSERT_TRUE(std::getline(in, second));
      const auto t = std::stoll(line.substr(0, line.find(',')));
      EXPECT_EQ(line + "\n" + second + "\n", text(t));
      seen.insert(line);
    }
    EXPECT_EQ(seen.size(), tasks.size());
    for (auto t : tasks) EXPECT_EQ(seen.count(fmt::format("{},{}", t, t * t)), 1u);
  }
}

TEST(Tasks, AFileThatCannotBeOpenedIsAnOutputError) {
  EXPECT_THROW(study::run_tasks({1}, [](std::int64_t) { return std::string("x\n"); },
                                (pdp_test::temp_dir() / "no-such-folder" / "x.csv").string(), 1),
               awcc::OutputError);
}

}  // namespace
