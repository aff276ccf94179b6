#include "correction/training.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "test_paths.hpp"

namespace {

// The columns of a pdp sweep CSV that training reads (and a scene column).
const std::string kHeader =
    "study,run,velocity,fs,duration,dx,dy,np,truth_velocity,truth_turbulence_intensity,awcc_velocity,awcc_turbulence_intensity,"
    "awcc_void_fraction,awcc_count_rate,awcc_windows_accepted,awcc_windows_total,fscc_velocity,fscc_r12_max,"
    "fscc_turbulence_intensity_chanson,reason";

// A sweep CSV row with the columns pdp train reads set, the rest empty.
std::string row(std::int64_t run, const std::map<std::string, std::string>& values) {
  const auto names = awcc::split_cells(kHeader);
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::string v;
    if (names[i] == "study") v = "42";
    else if (names[i] == "run") v = std::to_string(run);
    else if (auto it = values.find(names[i]); it != values.end()) v = it->second;
    out += (i ? "," : "") + v;
  }
  return out + "\n";
}

std::map<std::string, std::string> good(double u, double true_u, double windows = 500) {
  return {{"fs", "20000"}, {"duration", "45"}, {"dx", "0.005"}, {"dy", "0.001"}, {"np", "10"}, {"truth_velocity", std::to_string(true_u)},
          {"truth_turbulence_intensity", "0.2"}, {"awcc_velocity", std::to_string(u)},
          {"awcc_turbulence_intensity", "0.18"}, {"awcc_void_fraction", "0.2"}, {"awcc_count_rate", std::to_string(100 * u)},
          {"awcc_windows_accepted", std::to_string(static_cast<long>(windows))},
          {"awcc_windows_total", std::to_string(static_cast<long>(2 * windows))}};
}

// Training without cross-validation, small and quick: 30 trees, min leaf 3.
correction::TrainOptions quick_training(int features_per_split) {
  correction::TrainOptions o;
  o.trees = 30;
  o.folds = 0;
  o.min_windows = 10;
  o.min_leaf_grid = {3};
  o.min_leaf = 3;
  o.features_per_split_grid = {features_per_split};
  o.features_per_split = features_per_split;
  return o;
}

// A sampling rate drawn log-uniformly over 10 kHz-1 MHz, as the campaigns draw it.
double log_uniform_rate(std::mt19937_64& g) {
  return std::exp(std::log(1e4) + (std::log(1e6) - std::log(1e4)) * std::uniform_real_distribution<double>(0.0, 1.0)(g));
}

std::filesystem::path write(const std::string& name, const std::string& text) {
  const auto p = pdp_test::temp_dir() / name;
  std::ofstream(p) << text;
  return p;
}

TEST(Training, LoadCountsEveryExcludedRunByCause) {
  std::string csv = kHeader + "\n";
  csv += row(0, good(10, 9.5));
  csv += row(1, {{"reason", "synthesis failed: boom"}});  // a failed run has no truth
  auto undefined = good(10, 9.5);
  undefined["reason"] = "awcc: 0 of 12 windows accepted";
  undefined["awcc_velocity"] = "";
  csv += row(2, undefined);
  csv += row(3, good(10, 9.5, 99));
  csv += row(4, good(20, 19, 100));
  const auto set = correction::load_training_set({write("training_counts.csv", csv)}, 100);
  EXPECT_EQ(set.total, 5);
  EXPECT_EQ(set.excluded_error, 1);
  EXPECT_EQ(set.excluded_undefined, 1);
  EXPECT_EQ(set.excluded_windows, 1);
  ASSERT_EQ(set.rows.size(), 2u);
  EXPECT_EQ(set.rows[1].run, 4);
  EXPECT_EQ(set.rows[1].study, 42u);
  EXPECT_DOUBLE_EQ(set.rows[1].features.velocity, 20.0);
  EXPECT_DOUBLE_EQ(set.rows[1].true_velocity, 19.0);
  EXPECT_DOUBLE_EQ(set.rows[1].features.dy, 0.001);
  EXPECT_DOUBLE_EQ(set.rows[1].features.np, 10.0);
  // d32 by the feature contract: 1.5 u c / F = 1.5 x 20 x 0.2 / 2000.
  EXPECT_NEAR(set.rows[1].features.d32, 0.003, 1e-15);
  EXPECT_TRUE(set.processing_assumed);  // no processing columns: the default, said
  EXPECT_EQ(set.generator_versions, std::set<int>{1});  // no generator_version column: version 1
}

// Each row's generator version is read; sweeps of two versions load together
// (their statistics are the same) and the set says both, for the warning and
// the provenance.
TEST(Training, LoadRecordsTheGeneratorVersionsOfTheRows) {
  const std::string header = kHeader + ",generator_version";
  auto versioned = [&](std::int64_t run, const std::string& version) {
    auto r = row(run, good(10, 9.5));
    r.pop_back();
    return r + "," + version + "\n";
  };
  const auto v2 = write("training_v2.csv", header + "\n" + versioned(0, "2") + versioned(1, "2"));
  EXPECT_EQ(correction::load_training_set({v2}, 100).generator_versions, std::set<int>{2});
  // A version-1 sweep (no column) of another study beside it.
  auto old_row = row(0, good(10, 9.5));
  old_row.replace(0, 2, "43");
  const auto v1 = write("training_v1.csv", kHeader + "\n" + old_row);
  EXPECT_EQ(correction::load_training_set({v2, v1}, 100).generator_versions, (std::set<int>{1, 2}));
}

// The geometry processed (probe_dx, probe_dy) wins over the scene's dx and
// dy, which explicit tips override; rows processed differently are refused.
TEST(Training, LoadReadsTheProcessedGeometryAndOneProcessing) {
  const std::string header = kHeader + ",probe_dx,probe_dy,awcc_filter_a,awcc_roc,awcc_weighting,awcc_signal,awcc_subsample";
  auto cells = [&](std::int64_t run, const std::string& filter_a) {
    auto r = row(run, good(10, 9.5));
    r.pop_back();
    return r + ",0.008,0.0005," + filter_a + ",on,duration,binary,none\n";
  };
  auto set = correction::load_training_set({write("training_geometry.csv", header + "\n" + cells(0, "0.4"))}, 100);
  ASSERT_EQ(set.rows.size(), 1u);
  EXPECT_DOUBLE_EQ(set.rows[0].features.dx, 0.008);
  EXPECT_DOUBLE_EQ(set.rows[0].features.dy, 0.0005);
  EXPECT_FALSE(set.processing_assumed);
  EXPECT_TRUE(set.processing == correction::Processing{});
  try {
    (void)correction::load_training_set(
        {write("training_mixed.csv", header + "\n" + cells(0, "0.4") + cells(1, "0.3"))}, 100);
    FAIL();
  } catch (const awcc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("training_mixed.csv:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("filter A: model 0.4, results 0.3"), std::string::npos) << e.what();
  }
}

TEST(Training, LoadRefusesDuplicatesAndBadNumbersNamingTheLine) {
  std::string csv = kHeader + "\n" + row(0, good(10, 9.5)) + row(0, good(10, 9.5));
  try {
    (void)correction::load_training_set({write("training_dup.csv", csv)}, 100);
    FAIL();
  } catch (const awcc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("training_dup.csv:3: run 0"), std::string::npos) << e.what();
  }
  auto bad = good(10, 9.5);
  bad["awcc_count_rate"] = "3mm";
  csv = kHeader + "\n" + row(0, bad);
  try {
    (void)correction::load_training_set({write("training_bad.csv", csv)}, 100);
    FAIL();
  } catch (const awcc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("training_bad.csv:2: column awcc_count_rate = '3mm'"), std::string::npos) << e.what();
  }
  try {
    (void)correction::load_training_set({write("training_foreign.csv", "a,b\n1,2\n")}, 100);
    FAIL();
  } catch (const awcc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no column 'study'"), std::string::npos) << e.what();
  }
}

// An enum cell that names no value is refused with the file, the row and the
// value (it used to read as the default processing).
TEST(Training, AnUnknownProcessingValueIsRefusedNamingTheRowAndTheValue) {
  const std::string header = kHeader + ",awcc_filter_a,awcc_roc,awcc_weighting,awcc_signal,awcc_subsample";
  const std::string known[] = {"on", "duration", "binary", "none"};
  const std::string columns[] = {"awcc_roc", "awcc_weighting", "awcc_signal", "awcc_subsample"};
  auto processed = [&](std::int64_t run, std::size_t unknown) {
    auto r = row(run, good(10, 9.5));
    r.pop_back();
    r += ",0.4";
    for (std::size_t i = 0; i < 4; ++i) r += "," + (i == unknown ? std::string("Parabolic") : known[i]);
    return r + "\n";
  };
  // The known values read back as the defaults they name.
  const auto set = correction::load_training_set({write("training_known.csv", header + "\n" + processed(0, 4))}, 100);
  EXPECT_TRUE(set.processing == correction::Processing{});
  for (std::size_t i = 0; i < 4; ++i) {
    const auto file = fmt::format("training_unknown_{}.csv", i);
    try {
      (void)correction::load_training_set({write(file, header + "\n" + processed(0, 4) + processed(1, i))}, 100);
      FAIL() << columns[i];
    } catch (const awcc::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(fmt::format("{}:3: column {} = 'Parabolic' is not one of", file, columns[i])), std::string::npos)
          << what;
    }
  }
}

// Each column training needs, left out, is refused by its name.
TEST(Training, AMissingColumnIsRefusedByItsName) {
  const auto names = awcc::split_cells(kHeader);
  for (const auto& missing : {"study", "run", "dx", "dy", "np", "truth_velocity", "truth_turbulence_intensity",
                              "awcc_velocity", "awcc_turbulence_intensity", "awcc_void_fraction", "awcc_count_rate",
                              "awcc_windows_accepted", "reason"}) {
    std::string header;
    for (const auto& n : names)
      if (n != missing) header += (header.empty() ? "" : ",") + n;
    try {
      (void)correction::load_training_set({write("training_missing.csv", header + "\n")}, 100);
      FAIL() << missing;
    } catch (const awcc::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fmt::format("training_missing.csv: no column '{}'", missing)),
                std::string::npos)
          << e.what();
    }
  }
}

// Every training target is the ratio 1.1, so every quantile is 1.1 u: the
// scores follow by hand. Row A: truth 1.1 u (corrected error 0, covered; raw
// 1/1.1 - 1); row B: truth u (corrected 0.1, not covered; raw 0).
TEST(Training, ScoresAreTheDefinedStatistics) {
  std::vector<correction::TrainingRow> train;
  for (int i = 0; i < 50; ++i) {
    correction::TrainingRow r;
    r.run = i;
    r.features = {10.0 + i, 0.1, 0.2, 0.003, 0.005, 0.001, 10, 500};
    r.true_velocity = 1.1 * r.features.velocity;
    r.true_turbulence_intensity = 0.15;  // difference +0.05
    train.push_back(r);
  }
  correction::ForestOptions o;
  o.trees = 5;
  const auto model = correction::fit_model(train, correction::TargetForm::ratio, correction::TargetForm::difference, o, o, 100);
  auto a = train[10], b = train[20];
  b.true_velocity = b.features.velocity;
  b.true_turbulence_intensity = 0.1;
  const auto s = correction::score(model, {a, b});
  EXPECT_EQ(s.rows, 2);
  EXPECT_NEAR(s.velocity_rmse_corrected, std::sqrt(0.01 / 2), 1e-12);
  EXPECT_NEAR(s.velocity_rmse_raw, std::sqrt(std::pow(1 / 1.1 - 1, 2) / 2), 1e-12);
  EXPECT_NEAR(s.velocity_bias_corrected, 0.05, 1e-12);
  EXPECT_NEAR(s.velocity_median_abs_corrected, 0.05, 1e-12);  // median of {0, 0.1}
  EXPECT_NEAR(s.velocity_median_abs_raw, 0.5 * (1 - 1 / 1.1), 1e-12);
  EXPECT_DOUBLE_EQ(s.velocity_coverage80, 0.5);
  EXPECT_DOUBLE_EQ(s.velocity_coverage95, 0.5);
  EXPECT_NEAR(s.tu_rmse_corrected, std::sqrt(0.05 * 0.05 / 2), 1e-12);
  EXPECT_NEAR(s.tu_rmse_raw, std::sqrt((0.05 * 0.05 + 0.0) / 2), 1e-12);
  // A row outside the ranges is counted, not scored.
  auto c = a;
  c.features.dx = 1.0;
  EXPECT_EQ(correction::score(model, {a, c}).out_of_range, 1);
}

// The held-out split hashes run indices: the order of the rows in the files
// does not change the model.
TEST(Training, ModelDoesNotDependOnRowOrder) {
  std::mt19937_64 g(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  correction::TrainingSet set;
  for (int i = 0; i < 700; ++i) {
    correction::TrainingRow r;
    r.run = i;
    r.features = {1 + 49 * u(g), 0.35 * u(g), 0.4 * u(g), 0.01 * u(g), 0.01 * u(g), 0.002 * u(g), 10, 500};
    r.true_velocity = r.features.velocity * (1 - 0.1 * u(g));
    r.true_turbulence_intensity = r.features.turbulence_intensity + 0.05 * u(g);
    set.rows.push_back(r);
  }
  set.total = 700;
  correction::TrainOptions o;
  o.trees = 10;
  o.folds = 2;
  o.cv_trees = 3;
  o.min_leaf_grid = {3, 8};
  o.features_per_split_grid = {2, 7};
  // Two studies with the same run indices (two sweeps combined).
  for (int i = 0; i < 350; ++i) set.rows[static_cast<std::size_t>(i)].study = 7;
  for (int i = 350; i < 700; ++i) set.rows[static_cast<std::size_t>(i)].run -= 350;
  const auto first = correction::train_model(set, o);
  std::reverse(set.rows.begin(), set.rows.end());
  const auto second = correction::train_model(set, o);
  EXPECT_EQ(first.model.serialise(), second.model.serialise());
  EXPECT_EQ(first.predictions.size(), 140u);
  EXPECT_EQ(first.calibration_rows, 112);  // 20 % of the 560 not held out
  EXPECT_FALSE(first.model.calibration.empty());
  EXPECT_EQ(first.cv.size(), 2u * 2u * 2u * 2u);
}

// Two quick models of the same runs (no reduced model), of a feature set
// without and with a feature.
std::pair<correction::TrainResult, correction::TrainResult> without_and_with(const correction::TrainingSet& set,
                                                                             const std::string& without,
                                                                             const std::string& with) {
  auto o = quick_training(5);
  o.reduced = false;
  o.feature_set = without;
  auto first = correction::train_model(set, o);
  o.feature_set = with;
  return {std::move(first), correction::train_model(set, o)};
}

// The message with which training a feature set on these runs is refused
// (a test failure, and empty, when it trains).
std::string training_refusal(const std::string& file, const std::string& csv, const std::string& feature_set) {
  try {
    auto o = quick_training(5);
    o.reduced = false;
    o.feature_set = feature_set;
    (void)correction::train_model(correction::load_training_set({write(file, csv)}, 10), o);
  } catch (const awcc::OptionError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " trained a " << feature_set << " model";
  return {};
}

TEST(Training, TheLagFeatureLearnsABiasOfTheLagInSamples) {
  // The bias depends on the lag in samples L = dx fs / u only (AWCC's lag
  // quantisation: 30 % at L -> 0, 1.5 % at L = 100): the lag feature makes it
  // one split variable; without it the forest must find a product of three
  // features by axis-parallel splits, which 1,500 runs cannot resolve.
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::string csv = kHeader + "\n";
  for (int i = 0; i < 1500; ++i) {
    const double fs = log_uniform_rate(g);
    const double dx = 0.0005 + 0.0095 * u(g);
    const double measured = 1 + 49 * u(g);
    const double lag = dx * fs / measured;
    auto v = good(measured, measured * (1.0 - 0.3 / (1.0 + lag / 5.0)), 500);
    v["fs"] = fmt::format("{:.10g}", fs);
    v["dx"] = fmt::format("{:.10g}", dx);
    csv += row(i, v);
  }
  const auto [without, with] = without_and_with(correction::load_training_set({write("lag.csv", csv)}, 10),
                                                 "extended-yield", "extended-yield+lag");
  EXPECT_EQ(with.model.ranges.back().name, "lag_samples");
  EXPECT_LT(with.held_out.velocity_rmse_corrected, 0.5 * without.held_out.velocity_rmse_corrected)
      << with.held_out.velocity_rmse_corrected << " against " << without.held_out.velocity_rmse_corrected;
  const auto again = correction::CorrectionModel::parse(with.model.serialise(), "m.qrf");
  EXPECT_EQ(again.serialise(), with.model.serialise());
}

TEST(Training, TheScaleFeatureLearnsABiasOfTheTimeScaleRatio) {
  // AWCC's Tu falls short by a factor that depends on T_u / T_W only (the
  // windows average the velocity over their length, error E4: Tu_true =
  // Tu (1 + 1 / ratio)), with the ratio drawn log-uniformly over 0.2-20 and
  // independent of every other feature: without the feature no split can
  // find it, with it one does. A sweep CSV without the column cannot train
  // a +scale set, and says which feature is missing.
  std::mt19937_64 g(8);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::string header = kHeader + ",awcc_time_scale_ratio";
  std::string csv = header + "\n", without_column = kHeader + "\n";
  for (int i = 0; i < 1500; ++i) {
    const double ratio = std::exp(std::log(0.2) + (std::log(20.0) - std::log(0.2)) * u(g));
    const double measured = 1 + 49 * u(g), tu = 0.05 + 0.3 * u(g);
    auto v = good(measured, measured, 500);
    v["awcc_turbulence_intensity"] = fmt::format("{:.10g}", tu);
    v["truth_turbulence_intensity"] = fmt::format("{:.10g}", tu * (1.0 + 1.0 / ratio));
    without_column += row(i, v);
    csv += row(i, v);
    csv.back() = ',';
    csv += fmt::format("{:.10g}\n", ratio);
  }
  const auto [without, with] = without_and_with(correction::load_training_set({write("scale.csv", csv)}, 10),
                                                 "extended-yield", "extended-yield+scale");
  EXPECT_EQ(with.model.ranges.back().name, "time_scale_ratio");
  EXPECT_LT(with.held_out.tu_rmse_corrected, 0.5 * without.held_out.tu_rmse_corrected)
      << with.held_out.tu_rmse_corrected << " against "
      << without.held_out.tu_rmse_corrected;
  const auto no_column = correction::load_training_set({write("no-scale.csv", without_column)}, 10);
  try {
    auto o = quick_training(5);
    o.reduced = false;
    o.feature_set = "extended-yield+scale";
    (void)correction::train_model(no_column, o);
    ADD_FAILURE() << "a sweep without the ratio trained a +scale model";
  } catch (const awcc::OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("time_scale_ratio"), std::string::npos) << e.what();
  }
}

TEST(Training, TheFsccFeaturesLearnAwccsFilterBiasAndRunsWithoutFsccAreLeftOut) {
  // AWCC reads high by a factor 1 + b, b uniform over 0-0.2 and independent
  // of every AWCC feature (the windows its filter dropped), while FSCC takes
  // every bubble and reads the truth: only FSCC's velocity over AWCC's shows
  // b. Without +fscc the forest cannot do better than b's spread (RMSE about
  // 0.2 / sqrt(12) = 5.8 %); with it one split variable carries b. The 100
  // runs without an FSCC velocity train the set without +fscc and are left
  // out, counted, by the set with it.
  std::mt19937_64 g(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::string csv = kHeader + "\n";
  for (int i = 0; i < 1600; ++i) {
    const double truth = 1 + 49 * u(g), b = 0.2 * u(g);
    auto v = good(truth * (1 + b), truth, 500);
    if (i % 16 != 0) {
      v["fscc_velocity"] = fmt::format("{:.10g}", truth);
      v["fscc_r12_max"] = "0.5";
    }
    csv += row(i, v);
  }
  const auto set = correction::load_training_set({write("fscc.csv", csv)}, 10);
  const auto [without, with] = without_and_with(set, "extended-yield", "extended-yield+fscc");
  EXPECT_EQ(without.excluded_features, 0);
  EXPECT_EQ(with.excluded_features, 100);
  EXPECT_NE(with.model.provenance.find("100 without a feature of the set"), std::string::npos) << with.model.provenance;
  EXPECT_EQ(with.model.ranges[with.model.ranges.size() - 2].name, "fscc_awcc_ratio");
  EXPECT_GT(without.held_out.velocity_rmse_corrected, 0.04);
  EXPECT_LT(with.held_out.velocity_rmse_corrected, 0.5 * without.held_out.velocity_rmse_corrected)
      << with.held_out.velocity_rmse_corrected << " against " << without.held_out.velocity_rmse_corrected;
  // A row as the training runs, AWCC reading 10 % high: with FSCC the +fscc
  // forest corrects it to the truth; without FSCC it is not corrected and
  // the message names the feature it lacks.
  correction::Measurement m;
  m.velocity = 22.0;
  m.turbulence_intensity = 0.18;
  m.void_fraction = 0.2;
  m.bubble_count_rate = 2200;
  m.dx = 0.005, m.dy = 0.001, m.np = 10, m.fs = 20000, m.duration = 45, m.windows_accepted = 500;
  m.windows_total = 1000;
  m.fscc_velocity = 20.0;
  m.r12_max = 0.5;
  const auto corrected = with.model.correct(m);
  ASSERT_TRUE(corrected.corrected()) << corrected.message;
  EXPECT_NEAR(corrected.velocity->median(), 20.0, 0.6);
  m.fscc_velocity.reset();
  m.r12_max.reset();
  const auto lacking = with.model.correct(m);
  EXPECT_EQ(lacking.status, correction::CorrectionStatus::missing_feature);
  EXPECT_NE(lacking.message.find("fscc_awcc_ratio"), std::string::npos) << lacking.message;
  // No run with FSCC at all: refused, naming the feature.
  std::string none = kHeader + "\n";
  for (int i = 0; i < 200; ++i) none += row(i, good(2.0 + 0.01 * i, 2.0));
  const auto refused = training_refusal("no-fscc.csv", none, "extended-yield+fscc");
  EXPECT_NE(refused.find("fscc_awcc_ratio"), std::string::npos) << refused;
}

TEST(Training, ChansonsTuIdentifiesTheTruthAwccsTuCannotAndUndefinedIsZero) {
  // AWCC's Tu reads 0.2 whatever the truth (its flattening, at its worst),
  // true Tu uniform over 0.05-0.45: without a second reading the forest can
  // do no better than the truth's spread (RMSE 0.4 / sqrt(12) = 0.115).
  // Chanson's Tu reads the truth within 2 %, and is undefined (an empty
  // cell) below a true 0.1, as tau05 < T05 leaves it at low Tu: those runs
  // train with 0, none is left out, and the Tu RMSE falls below a third.
  std::mt19937_64 g(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::string csv = kHeader + "\n";
  for (int i = 0; i < 1600; ++i) {
    const double truth = 1 + 49 * u(g), tu = 0.05 + 0.4 * u(g);
    auto v = good(truth, truth, 500);
    v["truth_turbulence_intensity"] = fmt::format("{:.10g}", tu);
    v["awcc_turbulence_intensity"] = "0.2";
    v["fscc_velocity"] = fmt::format("{:.10g}", truth);
    v["fscc_r12_max"] = "0.5";
    if (tu >= 0.1) v["fscc_turbulence_intensity_chanson"] = fmt::format("{:.10g}", tu * (0.98 + 0.04 * u(g)));
    csv += row(i, v);
  }
  const auto set = correction::load_training_set({write("chanson.csv", csv)}, 10);
  const auto [without, with] = without_and_with(set, "extended-yield+fscc", "extended-yield+fscc+chanson");
  EXPECT_EQ(with.excluded_features, 0);
  EXPECT_EQ(with.model.ranges.back().name, "fscc_tu_chanson");
  EXPECT_EQ(with.model.ranges.back().min, 0.0);  // the undefined ones, as 0
  EXPECT_GT(without.held_out.tu_rmse_corrected, 0.09);
  EXPECT_LT(with.held_out.tu_rmse_corrected, without.held_out.tu_rmse_corrected / 3.0)
      << with.held_out.tu_rmse_corrected << " against " << without.held_out.tu_rmse_corrected;
  // A sweep CSV without the column does not state it: no run can train the set.
  std::string stripped;
  {
    std::stringstream in(csv);
    std::string line;
    const auto names = awcc::split_cells(kHeader);
    const auto drop = static_cast<std::size_t>(
        std::find(names.begin(), names.end(), "fscc_turbulence_intensity_chanson") - names.begin());
    while (std::getline(in, line)) {
      const auto cells = awcc::split_cells(line);
      std::string out;
      for (std::size_t k = 0; k < cells.size(); ++k)
        if (k != drop) out += (k == 0 ? "" : ",") + cells[k];
      stripped += out + "\n";
    }
  }
  const auto refused = training_refusal("no-chanson.csv", stripped, "extended-yield+fscc+chanson");
  EXPECT_NE(refused.find("fscc_tu_chanson"), std::string::npos) << refused;
}

TEST(Training, TheExtendedFeatureSetLearnsFromTheRecord) {
  // The bias depends on the sampling rate only (true u = measured u at
  // 1 MHz, 20 % below it at 10 kHz): a forest that sees fs removes it, one
  // that does not cannot. Rows read from a sweep CSV carry fs and duration.
  std::mt19937_64 g(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::string csv = kHeader + "\n";
  for (int i = 0; i < 1000; ++i) {
    const double fs = log_uniform_rate(g);
    const double measured = 1 + 49 * u(g);
    const double truth = measured * (1.0 - 0.2 * (std::log(1e6) - std::log(fs)) / (std::log(1e6) - std::log(1e4)));
    auto v = good(measured, truth, 10 + std::floor(1000 * u(g)));
    v["fs"] = fmt::format("{:.10g}", fs);
    v["duration"] = fmt::format("{:.10g}", 20 + 280 * u(g));
    // FSCC reads 10 % high, and one run in four has no AWCC velocity.
    v["fscc_velocity"] = fmt::format("{:.10g}", 1.1 * truth);
    v["fscc_r12_max"] = "0.5";
    if (i % 4 == 0) v["awcc_velocity"] = v["awcc_turbulence_intensity"] = "";
    csv += row(i, v);
  }
  const auto set = correction::load_training_set({write("extended.csv", csv)}, 10);
  ASSERT_EQ(set.rows.size(), 750u);
  ASSERT_EQ(set.fscc_rows.size(), 1000u);  // FSCC's forest takes the runs without AWCC too
  EXPECT_GT(set.rows[0].features.fs, 1e4 - 1);
  EXPECT_GT(set.rows[0].features.duration, 19.9);
  auto o = quick_training(3);
  double rmse[3];
  int k = 0;
  for (const char* features : {"measured", "extended", "extended-yield"}) {
    o.feature_set = features;
    o.features_per_split_grid = {3};
    o.features_per_split = 3;
    const auto r = correction::train_model(set, o);
    EXPECT_EQ(r.model.ranges.size(), correction::feature_set_names(features).size());
    EXPECT_EQ(correction::feature_set_of([&] {
                std::vector<std::string> n;
                for (const auto& fr : r.model.ranges) n.push_back(fr.name);
                return n;
              }()),
              features);
    rmse[k++] = r.held_out.velocity_rmse_corrected;
    EXPECT_EQ(r.model.fscc.has_value(), std::string(features) != "measured");
    if (r.model.fscc) {
      // FSCC's 10 % is a constant ratio: the forest removes it.
      EXPECT_NEAR(r.fscc_held_out.rmse_raw, 0.10, 1e-9);
      EXPECT_LT(r.fscc_held_out.rmse_corrected, 0.01);
      EXPECT_NE(r.model.provenance.find("FSCC forest"), std::string::npos);
      // It is scored apart on the runs AWCC cannot serve (one in four); the
      // 160 calibration runs hold about 40 of those, too few to calibrate
      // on, so all calibration runs are used and the model says so.
      EXPECT_GT(r.fscc_held_out_unserved.rows, 25);
      EXPECT_LT(r.fscc_held_out_unserved.rows, 80);
      EXPECT_LT(r.fscc_held_out_unserved.rmse_corrected, 0.01);
      EXPECT_NE(r.fscc_calibration.find("calibrated on all 160 calibration runs"), std::string::npos)
          << r.fscc_calibration;
      // A row without AWCC: the FSCC forest corrects its velocity, not its Tu.
      correction::Measurement m;
      m.void_fraction = 0.2;
      m.bubble_count_rate = 2000;
      m.dx = 0.005, m.dy = 0.001, m.np = 10, m.fs = 1e5, m.duration = 100, m.windows_accepted = 3;
      m.fscc_velocity = 22.0;
      m.r12_max = 0.5;
      const auto c = r.model.correct(m);
      ASSERT_TRUE(c.corrected()) << c.message;
      EXPECT_EQ(c.forest, "fscc");
      EXPECT_NEAR(c.velocity->median(), 20.0, 0.2);
      EXPECT_FALSE(c.turbulence_intensity);
      // Without FSCC either: AWCC's status, with both reasons.
      m.fscc_velocity.reset();
      const auto none = r.model.correct(m);
      EXPECT_EQ(none.status, correction::CorrectionStatus::no_awcc_velocity);
      EXPECT_NE(none.message.find("FSCC forest: FSCC gave no velocity"), std::string::npos) << none.message;
    }
    if (std::string(features) == "extended") {
      // With 60 % of the training runs calibrating (480, about 120 without
      // AWCC), the FSCC forest is calibrated on the runs it will correct.
      auto wide = o;
      wide.calibration = 0.6;
      const auto w = correction::train_model(set, wide);
      EXPECT_NE(w.fscc_calibration.find("calibration runs AWCC cannot serve"), std::string::npos) << w.fscc_calibration;
    }
    // The file keeps the feature set.
    const auto again = correction::CorrectionModel::parse(r.model.serialise(), "m.qrf");
    EXPECT_EQ(again.serialise(), r.model.serialise());
  }
  // Uniform bias over 0-20 % unexplained: RMSE about 0.2 / sqrt(12) = 5.8 %;
  // explained by fs it falls to the forest's resolution (well under 2 %).
  EXPECT_GT(rmse[0], 0.04);
  EXPECT_LT(rmse[1], 0.02);
  EXPECT_LT(rmse[2], 0.02);
  o.feature_set = "extensive";
  EXPECT_NE(o.validate().message.find("use measured"), std::string::npos);
  EXPECT_EQ(o.validate().quantity, "feature-set");
  o.feature_set = "measured";
  o.features_per_split_grid = {8};
  EXPECT_NE(o.validate().message.find("give 1 to 7"), std::string::npos);
  EXPECT_EQ(o.validate().quantity, "features-per-split");
  o.features_per_split_grid = {3};
  o.features_per_split = 3;
  EXPECT_TRUE(o.validate().ok()) << o.validate().message;
  // Calibration Tu bands out of order are refused, not sorted silently.
  o.calibration_tu_bands = {0.2, 0.1};
  EXPECT_NE(o.validate().message.find("calibration Tu bands"), std::string::npos);
  EXPECT_EQ(o.validate().quantity, "calibration-tu-bands");
}

// A model of one varying feature (velocity 1-2 m/s) whose forest learnt
// targets of spread `sd` (velocity in the value form: the target is the true
// velocity; Tu in the difference form, its spread sd / 10).
correction::CorrectionModel shifted_model(double sd, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(1.0, 2.0);
  correction::CorrectionModel m;
  m.velocity_form = correction::TargetForm::value;
  m.turbulence_form = correction::TargetForm::difference;
  m.min_windows = 1;
  correction::TrainingData v, t;
  v.features = t.features = 7;
  correction::Features f;
  f.turbulence_intensity = 0.2, f.void_fraction = 0.2, f.d32 = 3e-3, f.dx = 5e-3, f.dy = 1e-3, f.np = 10;
  for (int i = 0; i < 1000; ++i) {
    f.velocity = u(g);
    const auto x = f.vector();
    v.x.insert(v.x.end(), x.begin(), x.end());
    t.x.insert(t.x.end(), x.begin(), x.end());
    v.y.push_back(10.0 + sd * n(g));
    t.y.push_back(sd / 10.0 * n(g));
  }
  for (std::size_t j = 0; j < 7; ++j) m.ranges.push_back({correction::Features::names[j], j == 0 ? 1.0 : f.vector()[j], j == 0 ? 2.0 : f.vector()[j]});
  correction::ForestOptions o;
  o.trees = 10;
  o.min_leaf = 100;  // leaves hold the whole spread
  o.seed = seed;
  m.velocity = correction::QuantileForest::train(v, o);
  m.turbulence_intensity = correction::QuantileForest::train(t, o);
  return m;
}

// Runs of spread 1 (Tu: 0.1) around the same centres, with their windows.
std::vector<correction::TrainingRow> runs(int count, std::uint64_t seed, std::int64_t windows) {
  std::mt19937_64 g(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(1.0, 2.0);
  std::vector<correction::TrainingRow> rows(static_cast<std::size_t>(count));
  for (auto& r : rows) {
    r.features.velocity = u(g);
    r.features.turbulence_intensity = 0.2, r.features.void_fraction = 0.2, r.features.d32 = 3e-3;
    r.features.dx = 5e-3, r.features.dy = 1e-3, r.features.np = 10;
    r.features.windows_accepted = windows;
    r.true_velocity = 10.0 + n(g);
    r.true_turbulence_intensity = 0.2 + 0.1 * n(g);
  }
  return rows;
}

TEST(Training, TheRecordsDurationSaturatesAtItsLongestPercent) {
  // duration_cap: of durations 1..1000 s the longest 1 % (991-1000) lie
  // above the cap, 990; rows without a duration are not counted.
  std::vector<correction::TrainingRow> rows(1001);
  for (int i = 0; i < 1000; ++i) rows[static_cast<std::size_t>(i)].features.duration = 1000 - i;
  EXPECT_DOUBLE_EQ(correction::duration_cap(rows), 990.0);
  rows.resize(99);  // 1000..902: floor(0.99) = 0 above, the longest itself
  EXPECT_DOUBLE_EQ(correction::duration_cap(rows), 1000.0);
  EXPECT_DOUBLE_EQ(correction::duration_cap({}), 0.0);

  // Through training: both forests' duration range ends at the cap of their
  // training runs, below the longest run, and a row beyond it is held there:
  // the same quantiles at the cap and at twice the longest record.
  std::mt19937_64 g(8);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::string csv = kHeader + "\n";
  for (int i = 0; i < 1000; ++i) {
    const double measured = 1 + 49 * u(g);
    auto v = good(measured, measured * (0.9 + 0.2 * u(g)), 10 + std::floor(1000 * u(g)));
    v["fs"] = "100000";
    v["duration"] = fmt::format("{:.10g}", 20 * std::pow(15.0, u(g)));
    v["fscc_velocity"] = fmt::format("{:.10g}", measured);
    v["fscc_r12_max"] = "0.5";
    csv += row(i, v);
  }
  const auto set = correction::load_training_set({write("saturated.csv", csv)}, 10);
  double longest = 0.0;
  for (const auto& r : set.rows) longest = std::max(longest, r.features.duration);
  correction::TrainOptions o;
  o.trees = 10;
  o.folds = 0;
  o.min_windows = 10;
  o.feature_set = "extended";
  const auto r = correction::train_model(set, o);
  const auto& d = r.model.ranges[8];
  ASSERT_EQ(d.name, "duration");
  ASSERT_TRUE(r.model.fscc);
  const auto& fd = r.model.fscc->ranges[7];
  ASSERT_EQ(fd.name, "duration");
  for (double cap : {d.max, fd.max}) {
    std::size_t above = 0;
    for (const auto& row : set.rows) above += row.features.duration > cap;
    // 640 training runs: 6 above the cap; over all 1000 rows about 10.
    EXPECT_GE(above, 6u) << cap;
    EXPECT_LE(above, 25u) << cap;
    EXPECT_LT(cap, longest);
  }
  auto f = set.rows[0].features;
  f.duration = d.max;
  const auto at_cap = r.model.correct(f);
  f.duration = 2 * longest;
  const auto beyond = r.model.correct(f);
  ASSERT_TRUE(at_cap.corrected() && beyond.corrected()) << at_cap.why_not() << beyond.why_not();
  EXPECT_EQ(at_cap.velocity->quantiles, beyond.velocity->quantiles);
  ASSERT_EQ(beyond.notes.size(), 1u);
  EXPECT_NE(beyond.notes[0].find(fmt::format("corrected as {:.4g} s", d.max)), std::string::npos) << beyond.notes[0];
}

TEST(Calibration, ConformalOffsetsBringCoverageToNominal) {
  // The forest learnt a spread twice the runs' own: its 80 % interval covers
  // P(|Z| < 2 x 1.2816) = 99 % of them. Calibrated on n = 1000 runs, the
  // coverage of new runs is Beta-distributed around 1 - alpha with sd
  // sqrt(alpha (1 - alpha) / n) (1.3 % at 80 %, 0.7 % at 95 %); scored on
  // 4000 runs (sd 0.6 %, 0.3 %): 4.5 % and 2.5 % are more than 3 sd.
  const auto model = shifted_model(2.0, 1);
  const auto calibration_runs = runs(1000, 2, 500);
  const auto test_runs = runs(4000, 3, 500);
  const auto raw = correction::score(model, test_runs);
  EXPECT_GT(raw.velocity_coverage80, 0.97);
  auto calibrated = model;
  calibrated.calibration = correction::calibrate(model, calibration_runs, {30, 100});
  ASSERT_EQ(calibrated.calibration.velocity.size(), 3u);
  // Bands 0 and 1 have no calibration runs: they take the pooled offsets, which equal band 2's.
  EXPECT_EQ(calibrated.calibration.velocity[0], calibrated.calibration.velocity[2]);
  EXPECT_LT(calibrated.calibration.velocity[2][1], 0.0);  // narrowed
  const auto s = correction::score(calibrated, test_runs);
  EXPECT_NEAR(s.velocity_coverage80, 0.80, 0.045);
  EXPECT_NEAR(s.velocity_coverage95, 0.95, 0.025);
  EXPECT_NEAR(s.tu_coverage80, 0.80, 0.045);
  EXPECT_NEAR(s.tu_coverage95, 0.95, 0.025);
  // The median is the forest's: calibration moves only the interval ends.
  EXPECT_DOUBLE_EQ(s.velocity_rmse_corrected, raw.velocity_rmse_corrected);
}

TEST(Calibration, TuBandsAreCalibratedOnTheirOwn) {
  // The Tu forest learnt nothing of Tu (every training run had 0.2), so its
  // median is the measured Tu: runs measured at Tu 0.05 fall in the first Tu
  // band, at 0.25 in the third. The calm runs' velocities spread 1, the
  // turbulent ones' 0.5: each Tu band's 80 % interval is set by its own runs,
  // and bands without runs take the window band's pooled offsets.
  auto model = shifted_model(2.0, 4);
  model.ranges[1] = {"turbulence_intensity", 0.0, 0.5};  // both kinds inside
  auto calm = runs(600, 5, 500), turbulent = runs(600, 6, 500);
  for (auto& r : calm) r.features.turbulence_intensity = 0.05;
  for (auto& r : turbulent) {
    r.features.turbulence_intensity = 0.25;
    r.true_velocity = 10.0 + 0.5 * (r.true_velocity - 10.0);
  }
  std::vector<correction::TrainingRow> both(calm);
  both.insert(both.end(), turbulent.begin(), turbulent.end());
  auto m = model;
  m.calibration = correction::calibrate(model, both, {}, 0, {0.1, 0.2, 0.3});
  const auto& c = m.calibration;
  ASSERT_EQ(c.velocity.size(), 4u);  // one window band x four Tu bands
  EXPECT_EQ(c.tu_band(0.05), 0);
  EXPECT_EQ(c.tu_band(0.25), 2);
  EXPECT_GT(c.velocity[0][1], c.velocity[2][1] + 0.3);  // the calm band is wider
  EXPECT_LT(c.velocity[1][1], c.velocity[0][1]);        // empty: pooled, between the two
  EXPECT_GT(c.velocity[1][1], c.velocity[2][1]);
  EXPECT_EQ(c.velocity[1], c.velocity[3]);
  // New runs of each kind: nominal coverage (3000 runs: sd 0.7 %, bound 4 %).
  auto new_calm = runs(3000, 7, 500), new_turbulent = runs(3000, 8, 500);
  for (auto& r : new_calm) r.features.turbulence_intensity = 0.05;
  for (auto& r : new_turbulent) {
    r.features.turbulence_intensity = 0.25;
    r.true_velocity = 10.0 + 0.5 * (r.true_velocity - 10.0);
  }
  EXPECT_NEAR(correction::score(m, new_calm).velocity_coverage80, 0.80, 0.04);
  EXPECT_NEAR(correction::score(m, new_turbulent).velocity_coverage80, 0.80, 0.04);
  // Calibrated by windows alone, the two kinds miss nominal in opposite ways.
  auto pooled = model;
  pooled.calibration = correction::calibrate(model, both, {}, 0, {});
  EXPECT_GT(correction::score(pooled, new_calm).velocity_coverage80, 0.80 - 0.15);
  EXPECT_LT(correction::score(pooled, new_calm).velocity_coverage80, 0.75);
  EXPECT_GT(correction::score(pooled, new_turbulent).velocity_coverage80, 0.88);
  // The Tu bands survive the file.
  const auto again = correction::CorrectionModel::parse(m.serialise(), "m.qrf");
  EXPECT_EQ(again.calibration.tu_edges, c.tu_edges);
  EXPECT_EQ(again.calibration.velocity, c.velocity);
  EXPECT_EQ(again.calibration.turbulence_intensity, c.turbulence_intensity);
}

TEST(Calibration, BandsAreCalibratedOnTheirOwnAndUnknownWindowsTakeTheWidest) {
  // Runs with 10-29 windows spread 1, runs with 100+ spread 0.5: each band's
  // 80 % interval is set by its own runs.
  const auto model = shifted_model(2.0, 4);
  auto few = runs(600, 5, 20), many = runs(600, 6, 500);
  for (auto& r : many) r.true_velocity = 10.0 + 0.5 * (r.true_velocity - 10.0);
  std::vector<correction::TrainingRow> both(few);
  both.insert(both.end(), many.begin(), many.end());
  auto m = model;
  m.calibration = correction::calibrate(model, both, {30, 100});
  const auto& c = m.calibration;
  EXPECT_GT(c.velocity[0][1], c.velocity[2][1] + 0.3);  // the few-window band is wider
  // Band 1 (30-99 windows) has no runs: the pooled offsets, between the two.
  EXPECT_LT(c.velocity[1][1], c.velocity[0][1]);
  EXPECT_GT(c.velocity[1][1], c.velocity[2][1]);
  EXPECT_EQ(c.band(-1), -1);
  EXPECT_EQ(c.band(10), 0);
  EXPECT_EQ(c.band(30), 1);
  EXPECT_EQ(c.band(100), 2);
  EXPECT_NEAR(correction::score(m, runs(3000, 7, 20)).velocity_coverage80, 0.80, 0.04);
  auto narrow = runs(3000, 8, 500);
  for (auto& r : narrow) r.true_velocity = 10.0 + 0.5 * (r.true_velocity - 10.0);
  EXPECT_NEAR(correction::score(m, narrow).velocity_coverage80, 0.80, 0.04);
  // Unknown windows: each interval's widest band, so at least nominal for either kind.
  auto unknown = runs(3000, 9, -1);
  EXPECT_GT(correction::score(m, unknown).velocity_coverage80, 0.77);
  // The calibration survives the file.
  const auto again = correction::CorrectionModel::parse(m.serialise(), "m.qrf");
  EXPECT_EQ(again.calibration.window_edges, c.window_edges);
  EXPECT_TRUE(again.calibration.tu_edges.empty());
  EXPECT_EQ(again.calibration.velocity, c.velocity);
  EXPECT_EQ(again.calibration.turbulence_intensity, c.turbulence_intensity);
}

TEST(Calibration, TooFewRunsAreRefusedNotGuessed) {
  // k = ceil((n + 1)(1 - alpha)) > n needs an infinite offset: 10 runs cannot
  // calibrate a 95 % interval (k = 11), and no runs nothing at all.
  const auto model = shifted_model(2.0, 1);
  EXPECT_THROW((void)correction::calibrate(model, {}, {30, 100}), std::invalid_argument);
  EXPECT_THROW((void)correction::calibrate(model, runs(10, 2, 500), {}), std::invalid_argument);
  EXPECT_NO_THROW((void)correction::calibrate(model, runs(19, 2, 500), {}));  // k = 19
}

TEST(Calibration, ApplyKeepsTheQuantilesInOrder) {
  // A narrowing larger than an interval's half width stops at the median.
  // Levels 0.025 0.05 0.1 0.25 0.5 0.75 0.9 0.95 0.975; offsets of the 50,
  // 80, 90 and 95 % intervals.
  std::vector<double> t{-4, -3, -2, -1, 0, 1, 2, 3, 4};
  correction::Calibration::apply({5.0, -10.0, 0.0, 1.0}, t);
  // 50 % widened to -6..6; 80 % narrowed past the median, 90 % kept at
  // -3..3 and 95 % widened to -5..5: all held at least as wide as the 50 %.
  EXPECT_EQ(t, (std::vector<double>{-6, -6, -6, -6, 0, 6, 6, 6, 6}));
  std::vector<double> u{-4, -3, -2, -1, 0, 1, 2, 3, 4};
  correction::Calibration::apply({-5.0, 0.0, 0.0, 0.0}, u);
  EXPECT_EQ(u, (std::vector<double>{-4, -3, -2, 0, 0, 0, 2, 3, 4}));
  // Each offset moves its own pair of levels.
  std::vector<double> w{-4, -3, -2, -1, 0, 1, 2, 3, 4};
  correction::Calibration::apply({0.0, 0.0, 0.5, 0.0}, w);
  EXPECT_EQ(w, (std::vector<double>{-4, -3.5, -2, -1, 0, 1, 2, 3.5, 4}));
}

TEST(Training, ScoresByBandCountEachBandsRowsInsideTheirIntervalsAndTheirErrors) {
  // Four runs: Tu 0.15 with 20 windows at 20 kHz (two inside both intervals,
  // one inside the 95 % only, one outside both) and one Tu 0.32 with 500 windows at 500 kHz.
  auto prediction = [](double true_u, double tu, std::int64_t windows, double fs) {
    correction::HeldOutPrediction p;
    p.row.true_velocity = true_u;
    p.row.true_turbulence_intensity = tu;
    p.row.features.windows_accepted = windows;
    p.row.features.fs = fs;
    p.row.features.velocity = 10.5;              // raw AWCC
    p.row.features.turbulence_intensity = 0.12;  // raw AWCC
    p.correction.status = correction::CorrectionStatus::corrected;
    correction::CorrectedQuantity u, t;
    u.quantiles = {7, 7.5, 8, 9, 10, 11, 12, 12.5, 13};
    t.quantiles = {0.0, 0.05, 0.1, 0.12, 0.15, 0.18, 0.2, 0.3, 0.4};
    p.correction.velocity = u;
    p.correction.turbulence_intensity = t;
    return p;
  };
  const std::vector<correction::HeldOutPrediction> p{prediction(10, 0.15, 20, 2e4), prediction(11.5, 0.15, 20, 2e4),
                                                     prediction(12.5, 0.15, 20, 2e4), prediction(14, 0.15, 20, 2e4),
                                                     prediction(10, 0.32, 500, 5e5)};
  const auto table = correction::scores_by_band(p);
  auto band = [&](const std::string& name) {
    for (const auto& b : table)
      if (b.band == name) return b;
    ADD_FAILURE() << "no band " << name;
    return correction::BandScores{};
  };
  EXPECT_EQ(band("all").rows, 5);
  EXPECT_DOUBLE_EQ(band("all").velocity80, 3.0 / 5);
  EXPECT_DOUBLE_EQ(band("all").velocity95, 4.0 / 5);
  EXPECT_EQ(band("true Tu 0.1-0.2").rows, 4);
  EXPECT_DOUBLE_EQ(band("true Tu 0.1-0.2").velocity80, 2.0 / 4);
  EXPECT_DOUBLE_EQ(band("true Tu 0.1-0.2").tu80, 1.0);
  EXPECT_DOUBLE_EQ(band("true Tu 0.3-0.35").tu80, 0.0);  // 0.32 is above q0.9 = 0.2
  EXPECT_DOUBLE_EQ(band("true Tu 0.3-0.35").tu95, 1.0);
  EXPECT_EQ(band("windows 10-29").rows, 4);
  EXPECT_EQ(band("windows 100+").rows, 1);
  EXPECT_EQ(band("fs 0-50 kHz").rows, 4);
  EXPECT_EQ(band("fs 200 kHz+").rows, 1);
  for (const auto& b : table) EXPECT_NE(b.band, "windows 30-99");  // empty bands are left out
  {
    // A band holds its lower end: Tu 0.35 is the campaign's top band, not 0.3-0.35.
    const auto edge = correction::scores_by_band({prediction(10, 0.35, 500, 5e5)});
    bool top = false;
    for (const auto& b : edge) {
      EXPECT_NE(b.band, "true Tu 0.3-0.35");
      if (b.band == "true Tu 0.35-0.45") top = b.rows == 1;
    }
    EXPECT_TRUE(top);
  }
  // Errors over the band's four runs, from the definitions: velocity
  // relative (corrected median 10 against 10, 11.5, 12.5, 14), Tu absolute.
  const auto& tu = band("true Tu 0.1-0.2");
  const double e[] = {0.0, 10 / 11.5 - 1, 10 / 12.5 - 1, 10.0 / 14 - 1};
  const double r[] = {0.05, 10.5 / 11.5 - 1, 10.5 / 12.5 - 1, 10.5 / 14 - 1};
  EXPECT_NEAR(tu.velocity_rmse_corrected, std::sqrt((e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]) / 4), 1e-12);
  EXPECT_NEAR(tu.velocity_rmse_raw, std::sqrt((r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]) / 4), 1e-12);
  EXPECT_NEAR(tu.velocity_median_abs_corrected, (-e[1] - e[2]) / 2, 1e-12);  // the mean of the middle two
  EXPECT_NEAR(tu.velocity_median_abs_raw, (-r[1] - r[2]) / 2, 1e-12);         // of 0.05, 0.087, 0.16, 0.25
  EXPECT_NEAR(tu.tu_rmse_raw, 0.03, 1e-12);
  EXPECT_NEAR(tu.tu_median_abs_raw, 0.03, 1e-12);
  EXPECT_NEAR(tu.tu_rmse_corrected, 0.0, 1e-12);

  // A run left uncorrected counts in its band's runs, not in the scores.
  auto q = p;
  q[0].correction = correction::Correction{};
  q[0].correction.status = correction::CorrectionStatus::too_few_windows;
  const auto fewer = correction::scores_by_band(q);
  EXPECT_EQ(fewer.front().runs, 5);
  EXPECT_EQ(fewer.front().rows, 4);
  EXPECT_DOUBLE_EQ(fewer.front().velocity80, 2.0 / 4);  // runs 2 and 5 remain inside
  // The runs both models correct, and a set of other runs refused.
  const auto both = correction::corrected_by_both(p, q);
  ASSERT_EQ(both.size(), 4u);
  EXPECT_EQ(both.front().row.true_velocity, 11.5);
  auto shuffled = q;
  shuffled[1].row.run = 7;
  EXPECT_THROW(correction::corrected_by_both(p, shuffled), std::invalid_argument);
  // The report's coverage on the 4 runs both correct (the same quantiles in
  // both): true u 11.5, 12.5, 14, 10 against [8, 12] and [7, 13] -> 2/4 and
  // 3/4; true Tu 0.15 (three) and 0.32 against [0.1, 0.2] and [0, 0.4] -> 3/4, 4/4.
  const auto report = correction::comparison_report(p, q, "old.qrf");
  EXPECT_NE(report.find("old.qrf"), std::string::npos);
  EXPECT_EQ(report.find("model Tu"), std::string::npos);
  const auto all_line = report.substr(report.find("\n  all ", report.find("Coverage")) + 1);
  EXPECT_EQ(all_line.substr(0, all_line.find('\n')),
            fmt::format("  {:<28} {:>6}   {:5.1f} / {:5.1f}  {:5.1f} / {:5.1f}  {:5.1f} / {:5.1f}  {:5.1f} / {:5.1f}", "all",
                        4, 50.0, 50.0, 75.0, 75.0, 75.0, 75.0, 100.0, 100.0));
}

}  // namespace
