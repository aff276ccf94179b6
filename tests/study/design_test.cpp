#include "study/design.hpp"

#include <gtest/gtest.h>

#include <sstream>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/probe_correction.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

std::filesystem::path write(const std::string& name, const std::string& text) {
  const auto p = pdp_test::test_file(name);
  std::ofstream(p) << text;
  return p;
}

const std::string kTwoConditions =
    "[design]\nseeds = 3\nseed = 7\n"
    "[conditions.upper]\nvelocity = \"10m/s\"\ntu = 0.25\nvoid-fraction = 0.25\nbubble-diameter = \"3mm\"\n"
    "[conditions.wall]\nvelocity = [\"2m/s\", \"4m/s\"]\ntu = [0.1, 0.2]\nvoid-fraction = [0.02, 0.1, \"log\"]\n"
    "time-scale = \"20ms\"\n"
    "[candidates]\ndx = [\"2mm\", \"5mm\"]\ndy = [\"0mm\", \"1mm\"]\nnp = [5, 10]\nfs = [\"100kHz\"]\n"
    "duration = [\"20s\", \"40s\"]\n";

std::string error_of(const std::string& text) {
  try {
    (void)study::load_design(write("bad.toml", text));
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(DesignFile, ReadsConditionsCandidatesAndTheCurrentProbe) {
  const auto d = study::load_design(write("two.toml", kTwoConditions + "[current]\ndx = \"7mm\"\ndy = \"1mm\"\nnp = 10\n"
                                                                      "fs = \"100kHz\"\nduration = \"20s\"\n"));
  EXPECT_EQ(d.seeds, 3);
  ASSERT_EQ(d.conditions.size(), 2u);
  EXPECT_EQ(d.conditions[0].name, "upper");
  EXPECT_EQ(d.conditions[1].name, "wall");
  // Conditions keep the file's order, not their names'.
  const auto z = study::load_design(write("order.toml", "[conditions.z]\ntu = 0.2\n[conditions.a]\ntu = 0.3\n"));
  EXPECT_EQ(z.conditions[0].name, "z");
  EXPECT_EQ(d.conditions[1].ranges.at("velocity"), (std::pair{2.0, 4.0}));
  EXPECT_TRUE(d.conditions[1].log_ranges.count("void-fraction"));
  // The current probe's geometry joins the grid's four.
  ASSERT_EQ(d.geometries.size(), 5u);
  EXPECT_EQ(d.geometries.back(), (std::pair{7e-3, 1e-3}));
  EXPECT_EQ(d.candidates().size(), 5u * 2u * 1u * 2u);
  EXPECT_EQ(d.tasks(), 2 * 1 * 2 * 3);
  EXPECT_EQ(d.rows_per_task(), 10);
}

TEST(DesignFile, BadDefinitionsNameTheTableTheKeyAndTheFix) {
  EXPECT_NE(error_of("[candidates]\nnp = [5]\n").find("give at least one condition"), std::string::npos);
  EXPECT_NE(error_of("[conditions.a]\ntu = 0.2\ndx = \"5mm\"\n").find("[conditions.a] dx"), std::string::npos);
  EXPECT_NE(error_of("[conditions.a]\nrho-xz = [-0.5, 0]\n").find("take ranges"), std::string::npos);
  EXPECT_NE(error_of("[conditions.a]\ntu = [0, 0.2]\n").find("Tu >= 0.02"), std::string::npos);
  EXPECT_NE(error_of("[conditions.a]\nvelocity = 3\n").find("[conditions.a] velocity"), std::string::npos);  // no unit
  EXPECT_NE(error_of("[conditions.a]\ntu = 0.2\n[candidates]\ndx = [\"2mm\"]\nprobes = [\"5mm,1mm\"]\n")
                .find("either probes or dx and dy"),
            std::string::npos);
  EXPECT_NE(error_of("[conditions.a]\ntu = 0.2\n[current]\ndx = \"5mm\"\n").find("give dy"), std::string::npos);
  EXPECT_NE(error_of("[conditions.a]\ntu = 0.2\n[flow]\nx = 1\n").find("unknown table"), std::string::npos);
  EXPECT_NE(error_of("[conditions.a]\ntu = 0.2\n[candidates]\ndx = [\"0mm\"]\n").find("above 0"), std::string::npos);
  EXPECT_NE(error_of("[conditions]\nvelocity = \"3m/s\"\n").find("[conditions.NAME]"), std::string::npos);
}

TEST(DesignTasks, EveryRecordDrawsItsFlowFromItsConditionAndNumberOnly) {
  const auto d = study::load_design(write("two.toml", kTwoConditions));
  // Task order: condition, fs, duration, record.
  const auto t = d.task((0 * 2 + 1) * 3 + 1);  // condition 0 (upper), second duration, record 1
  EXPECT_EQ(t.condition, 0u);
  EXPECT_EQ(t.record, 1);
  EXPECT_EQ(t.duration, 40.0);
  // Leading tip at the origin, then one trailing tip per geometry.
  ASSERT_EQ(t.scene.tips.size(), 1 + d.geometries.size());
  EXPECT_EQ(t.scene.tips[0], (synth::Vec3{0, 0, 0}));
  EXPECT_EQ(t.scene.tips[4], (synth::Vec3{5e-3, 1e-3, 0}));
  // The step the closest pair alone would get: min(T / 50, 2 mm / u / 10).
  EXPECT_DOUBLE_EQ(t.scene.realisation_step, std::min(t.scene.time_scale / 50.0, 2e-3 / 10.0 / 10.0));
  for (std::int64_t i = 0; i < d.tasks(); ++i) {
    const auto a = d.task(i);
    const auto& c = d.conditions[a.condition];
    if (c.name != "wall") continue;
    EXPECT_GE(a.scene.velocity, 2.0);
    EXPECT_LE(a.scene.velocity, 4.0);
    EXPECT_GE(a.scene.void_fraction, 0.02);
    EXPECT_LE(a.scene.void_fraction, 0.1);
    EXPECT_DOUBLE_EQ(a.scene.tu_y, 0.5 * a.scene.tu);  // the default anisotropy
    // The same record at the other duration: the same flow and seed.
    const auto other = d.task(i % 3 + (a.duration == 20.0 ? 3 : 0) + 6);
    EXPECT_EQ(other.record, a.record);
    EXPECT_EQ(other.scene.seed, a.scene.seed);
    EXPECT_EQ(other.scene.velocity, a.scene.velocity);
  }
  // Another candidate list draws the same flows and seeds.
  auto more = kTwoConditions;
  more.replace(more.find("dx = [\"2mm\", \"5mm\"]"), 19, "dx = [\"1mm\", \"2mm\", \"5mm\"]");
  const auto e = study::load_design(write("more.toml", more));
  EXPECT_NE(study::design_id(e), study::design_id(d));
  for (std::int64_t i = 0; i < d.tasks(); ++i) {
    EXPECT_EQ(e.task(i).scene.seed, d.task(i).scene.seed);
    EXPECT_EQ(e.task(i).scene.void_fraction, d.task(i).scene.void_fraction);
  }
}

TEST(DesignScores, ErrorStatisticsAreTheDefinitions) {
  const auto s = study::error_stats({0.1, -0.1, 0.3});
  EXPECT_EQ(s.count, 3);
  EXPECT_NEAR(s.bias, 0.1, 1e-15);
  EXPECT_NEAR(s.spread, 0.2, 1e-15);  // sqrt((0 + 0.04 + 0.04) / 2)
  EXPECT_NEAR(s.rms, std::sqrt((0.01 + 0.01 + 0.09) / 3), 1e-15);
  // rms^2 = bias^2 + (n - 1) / n spread^2
  EXPECT_NEAR(s.rms * s.rms, s.bias * s.bias + 2.0 / 3.0 * s.spread * s.spread, 1e-15);
  EXPECT_EQ(study::error_stats({}).count, 0);
}

// Rows of two conditions for candidates with planted errors: u = (1 + eu) u_true, Tu = (1 + et) Tu_true.
study::DesignRow planted(const study::DesignCandidate& c, const std::string& condition, double eu, double et,
                         double seconds = 0.01) {
  study::DesignRow r;
  r.condition = condition;
  r.candidate = c;
  r.truth_velocity = 4.0;
  r.truth_turbulence_intensity = 0.2;
  r.awcc_velocity = 4.0 * (1 + eu);
  r.awcc_turbulence_intensity = 0.2 * (1 + et);
  r.corrected_velocity = 4.0 * (1 + eu / 2);  // the model halves the error
  r.corrected_turbulence_intensity = 0.2 * (1 + et / 2);
  r.windows_accepted = 50;
  r.windows_total = 100;
  r.seconds_awcc = seconds;
  return r;
}

TEST(DesignScores, RankingIsByFailuresThenTheWorstConditionThenTheShorterRecord) {
  auto d = study::load_design(write("rank.toml", "[conditions.a]\ntu = 0.2\n[conditions.b]\ntu = 0.2\n"
                                               "[candidates]\nprobes = [\"2mm,0mm\", \"5mm,0mm\", \"9mm,0mm\"]\n"
                                               "np = [10]\nfs = [\"100kHz\"]\nduration = [\"20s\", \"30s\"]\n"));
  auto all = d.candidates();
  ASSERT_EQ(all.size(), 6u);
  // Rows for four of them: 2 mm at 20 s, 5 mm at 30 s, 9 mm at 20 s, 5 mm at 20 s.
  const std::vector<study::DesignCandidate> c{all[0], all[3], all[4], all[2]};
  ASSERT_EQ(c[1].duration, 30.0);
  ASSERT_EQ(c[2].duration, 20.0);
  std::vector<study::DesignRow> rows;
  // Candidate 0: 0.2 in a, 0.0 in b (worst 0.2); candidate 1: 0.1 in both (worst 0.1, mean 0.1);
  // candidate 2: as 1 but a shorter record; candidate 3: perfect but one record without a value.
  for (int k = 0; k < 2; ++k) {
    rows.push_back(planted(c[0], "a", 0.2, 0.2));
    rows.push_back(planted(c[0], "b", 0.0, 0.0));
    rows.push_back(planted(c[1], "a", 0.1, 0.1));
    rows.push_back(planted(c[1], "b", 0.1, 0.1));
    rows.push_back(planted(c[2], "a", 0.1, 0.1, 0.02));
    rows.push_back(planted(c[2], "b", 0.1, 0.1, 0.02));
    rows.push_back(planted(c[3], "a", 0.0, 0.0));
    rows.push_back(planted(c[3], "b", 0.0, 0.0));
  }
  rows.back().awcc_velocity.reset();
  rows.back().corrected_velocity.reset();
  const auto ranked = study::rank_candidates(d, rows);
  ASSERT_EQ(ranked.size(), 6u);
  // Corrected values: errors halved; score = |u| + |Tu| RMS.
  EXPECT_EQ(ranked[0].candidate, c[2]);  // the same errors as c[1], a shorter record
  EXPECT_NEAR(ranked[0].objective, 0.1, 1e-12);
  EXPECT_EQ(ranked[1].candidate, c[1]);
  EXPECT_EQ(ranked[2].candidate, c[0]);
  EXPECT_NEAR(ranked[2].objective, 0.2, 1e-12);
  EXPECT_EQ(ranked[3].candidate, c[3]);  // a record without a value ranks after
  EXPECT_EQ(ranked[3].failures, 1);
  EXPECT_EQ(ranked[4].failures, 2);      // candidates without records: no value anywhere
  EXPECT_TRUE(std::isinf(ranked[5].objective));
  EXPECT_NEAR(ranked[2].conditions[0].raw_u.bias, 0.2, 1e-12);
  // Every record of a candidate has the same errors: no resample changes
  // the order, and the first is first in all of them.
  EXPECT_EQ(ranked[0].best_share, 1.0);
  EXPECT_EQ(ranked[1].best_share, 0.0);
  EXPECT_NEAR(ranked[2].conditions[0].data_yield, 0.5, 1e-12);
  // The mean over conditions puts candidate 0 (mean 0.1) level with 1 and
  // ahead of 2 (cost); raw values double every score.
  d.objective = "mean";
  const auto mean = study::rank_candidates(d, rows);
  EXPECT_NEAR(mean[0].objective, 0.1, 1e-12);
  d.values = "raw";
  const auto raw = study::rank_candidates(d, rows);
  EXPECT_NEAR(raw[0].objective, 0.2, 1e-12);
  // Records that disagree: c[1] and c[2] swap their corrected errors (5 and
  // 15 %) between the two records, and c[3]'s record without a value is
  // record 1 of condition b: a resample that leaves that record out (1 in 4)
  // puts the error-free c[3] first, the others do not. So two candidates
  // share the firsts, and each resample has exactly one first.
  d.values = "corrected";
  d.objective = "worst-case";
  auto noisy = rows;
  for (auto& r : noisy) {
    r.record = static_cast<int>(&r - noisy.data()) / 8;  // two records of 8 rows
    const bool swap = (r.candidate == c[1]) == (r.record == 0);
    if (r.candidate == c[1] || r.candidate == c[2]) {
      const double e = swap ? 0.05 : 0.15;
      r.corrected_velocity = 4.0 * (1 + e), r.corrected_turbulence_intensity = 0.2 * (1 + e);
    }
  }
  const auto shares = study::rank_candidates(d, noisy);
  double total = 0.0;
  for (const auto& r : shares) total += r.best_share;
  EXPECT_NEAR(total, 1.0, 1e-12);
  for (const auto& r : shares) {
    if (r.candidate == c[3]) {
      EXPECT_GT(r.best_share, 0.1);  // about 1/4 of 200
      EXPECT_LT(r.best_share, 0.45);
    }
  }
  EXPECT_LT(shares[0].best_share, 0.9);
  // A needle scales every velocity of its candidate by the predicted ratio:
  // the same rows, ranked with a 1 mm needle, carry that ratio in u's bias.
  auto with_needle = d;
  with_needle.needles = {0.0, 1e-3};
  for (auto& r : rows) r.void_fraction = 0.1, r.count_rate = 80.0;
  const auto needled = study::rank_candidates(with_needle, rows);
  ASSERT_EQ(needled.size(), 12u);
  for (const auto& n : needled) {
    if (n.candidate.needle == 0.0 || n.candidate.dx != c[1].dx || n.candidate.duration != c[1].duration) continue;
    const double ratio = study::needle_velocity_ratio(4.0, 0.1, 80.0, c[1].dx, 1e-3);
    EXPECT_NEAR(n.conditions[0].raw_u.bias, ratio * 1.1 - 1.0, 1e-12);
    EXPECT_NEAR(n.conditions[0].raw_tu.bias, 0.1, 1e-12);  // Tu is left alone
  }
  // The ranked CSV: one row per candidate and condition, best first.
  const auto csv = study::ranked_csv(ranked, d);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 6 * 2);
  EXPECT_EQ(csv.substr(csv.find('\n') + 1, 2), "1,");
  // The header is the declaration; every row has a cell per declared column,
  // and the ranking the report would otherwise have to guess.
  std::vector<std::string> names;
  for (const auto& column : study::ranked_columns()) names.emplace_back(column.name);
  std::istringstream lines(csv);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(awcc::split_cells(line), names);
  const auto at = [&](std::string_view name) {
    return static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
  };
  while (std::getline(lines, line)) {
    const auto cells = awcc::split_cells(line);
    ASSERT_EQ(cells.size(), names.size()) << line;
    EXPECT_EQ(cells[at("ranking")], d.objective);
    EXPECT_EQ(cells[at("values")], d.values);
  }
  auto worst = d;
  worst.objective = "worst-case";
  worst.values = "corrected";
  const auto worst_csv = study::ranked_csv(study::rank_candidates(worst, rows), worst);
  EXPECT_NE(worst_csv.find(",worst-case,corrected,"), std::string::npos);
}

TEST(DesignScores, TheNeedlesSlowingIsTheInverseOfTheProbeCorrection) {
  // u_m = ratio u0 is the measured velocity whose correction (METHOD 9)
  // gives back u0: by construction, to the bisection's tolerance.
  const double u0 = 3.0, c = 0.08, f = 60.0, dx = 5e-3;
  const double r = study::needle_velocity_ratio(u0, c, f, dx, 0.6e-3);
  EXPECT_LT(r, 1.0);
  EXPECT_GT(r, 0.8);
  awcc::ProbeCorrectionOptions o;
  o.enabled = true;
  o.needle_diameter = 0.6e-3;
  const auto back = awcc::correct_window(r * u0, c, f, dx, o);
  ASSERT_EQ(back.outcome, awcc::CorrectionOutcome::corrected);
  EXPECT_NEAR(back.velocity, u0, 1e-6 * u0);
  // A thicker needle slows more; no needle, or c above 0.3 (not bubbly), not at all.
  EXPECT_LT(study::needle_velocity_ratio(u0, c, f, dx, 1.2e-3), r);
  EXPECT_EQ(study::needle_velocity_ratio(u0, c, f, dx, 0.0), 1.0);
  EXPECT_EQ(study::needle_velocity_ratio(u0, 0.35, f, dx, 0.6e-3), 1.0);
}

TEST(DesignRows, WrittenRowsReadBackAndForeignOnesAreRefused) {
  study::DesignRow r = planted({3e-3, 0.5e-3, 10, 1e5, 20}, "wall", 0.05, -0.1);
  r.task = 4;
  r.record = 1;
  r.seed = 18446744073709551615ull;
  r.correction_status = "corrected";
  r.correction_forest = "awcc";
  study::DesignRow failed = r;
  failed.awcc_velocity.reset();
  failed.corrected_velocity.reset();
  failed.correction_forest.clear();
  const auto path = pdp_test::test_file("runs.csv");
  std::ofstream(path) << study::design_rows_header() << "\n"
                      << study::design_row_text(r, 99) << "\n"
                      << study::design_row_text(failed, 99) << "\n"
                      << study::design_row_text(r, 99).substr(0, 30);  // cut short by a crash
  const auto rows = study::read_design_rows(path, 99);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].seed, r.seed);
  EXPECT_EQ(rows[0].candidate, r.candidate);
  EXPECT_DOUBLE_EQ(*rows[0].awcc_velocity, *r.awcc_velocity);
  EXPECT_FALSE(rows[1].awcc_velocity);
  EXPECT_EQ(rows[1].correction_forest, "");
  EXPECT_THROW((void)study::read_design_rows(path, 98), awcc::InputError);
  EXPECT_TRUE(study::read_design_rows(pdp_test::test_file("absent.csv"), 99).empty());
}

TEST(DesignRows, AnInterruptedDesignResumesWithoutItsCutShortRecords) {
  const auto d = study::load_design(write("resume.toml", kTwoConditions));
  ASSERT_EQ(d.rows_per_task(), 8);
  const auto path = pdp_test::test_file("resume.runs.csv");
  std::string text = study::design_rows_header() + "\n";
  // Tasks 0 and 2 whole, task 5 cut short after three of its eight rows.
  for (const auto& [task, rows] : {std::pair{0, 8}, std::pair{2, 8}, std::pair{5, 3}}) {
    for (int k = 0; k < rows; ++k) {
      auto r = planted({3e-3, 0.5e-3, 10, 1e5, 20}, "wall", 0.01 * k, 0.0);
      r.task = task;
      text += study::design_row_text(r, 42) + "\n";
    }
  }
  std::ofstream(path) << text;
  const auto resumed = study::resume_design(d, {path}, 42);
  EXPECT_EQ(resumed.done, (std::set<std::int64_t>{0, 2}));
  EXPECT_EQ(resumed.cut_short, 1);
  const auto kept = study::read_design_rows(path, 42);
  EXPECT_EQ(kept.size(), 16u);
  for (const auto& r : kept) EXPECT_NE(r.task, 5);
  // A fresh file gets its header; a second look finds the same.
  const auto fresh = pdp_test::test_file("fresh.runs.csv");
  std::filesystem::remove(fresh);
  EXPECT_TRUE(study::resume_design(d, {fresh}, 42).done.empty());
  std::ifstream in(fresh);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, study::design_rows_header());
  EXPECT_EQ(study::resume_design(d, {path}, 42).done, resumed.done);
}

TEST(DesignRecords, EveryPairOfTheMultiTipProbeRecoversThePlantedVelocity) {
  // A short record of a steady, gently turbulent flow: every trailing tip
  // sees the leading tip's bubbles, and AWCC recovers the planted 4 m/s
  // within its lag quantisation (1 sample of 10 us at 2 mm is 2 % of u).
  const auto d = study::load_design(write("steady.toml",
                                        "[design]\nseeds = 2\n[conditions.steady]\nvelocity = \"4m/s\"\ntu = 0.05\n"
                                        "void-fraction = 0.1\nbubble-diameter = \"3mm\"\ntime-scale = \"50ms\"\n"
                                        "[candidates]\ndx = [\"2mm\", \"5mm\"]\ndy = [\"0mm\", \"0.5mm\"]\nnp = [5, 10]\n"
                                        "fs = [\"100kHz\"]\nduration = [\"4s\"]\n"));
  const auto task = d.task(1);
  const auto rows = study::run_design_task(d, task, nullptr, {});
  ASSERT_EQ(rows.size(), 8u);
  for (const auto& r : rows) {
    EXPECT_EQ(r.truth_velocity, rows[0].truth_velocity);  // one flow for every pair
    ASSERT_TRUE(r.awcc_velocity) << r.candidate.dx << " " << r.candidate.dy;
    EXPECT_NEAR(*r.awcc_velocity / r.truth_velocity, 1.0, 0.03) << r.candidate.dx << " " << r.candidate.dy;
    EXPECT_GT(r.windows_accepted, 10);
    EXPECT_TRUE(r.correction_status.empty());  // no model
  }
  // Rows in geometry, then Np order; the same task gives the same numbers.
  EXPECT_EQ(rows[1].candidate.np, 10);
  EXPECT_EQ(rows[2].candidate.dy, 0.5e-3);
  const auto again = study::run_design_task(d, task, nullptr, {});
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(again[i].awcc_velocity, rows[i].awcc_velocity);
    EXPECT_EQ(again[i].awcc_turbulence_intensity, rows[i].awcc_turbulence_intensity);
  }
  // Each tip of the multi-tip probe sees the void fraction a two-tip probe would.
  const auto syn = synth::synthesise(task.scene);
  for (const auto& tip : syn.truth.tips) EXPECT_NEAR(tip.void_fraction, syn.truth.tips[0].void_fraction, 0.015);
}

}  // namespace
