// A profile's rows (correction/profile_rows.hpp) are built by one velocity
// rule whether their fields come from the ProcessResults in memory or from
// the process JSON and the profile CSV they were written to: real
// recordings of every velocity source (AWCC, FSCC, the corrected AWCC
// median), corrected and not, give the same rows, hence the same flow.
// The JSON holds each double exactly (json_text writes the shortest text that
// reads back as the same double): its rows and flow are identical. The CSV
// writes 10 significant digits ({:.10g}): a value moves by at most half a
// unit of its tenth digit, a relative 5e-10, which the rows are held to. The
// flow of those rows moves by the same order through functions of modest
// slope (trapezoids, log-linear least squares, quantiles of draws made with
// the same normal scores), and the fits' golden section stops at about 1e-9
// of D: its values are held to a relative 1e-7.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "awcc/process.hpp"
#include "awcc/serialise.hpp"
#include "correction/model.hpp"
#include "correction/profile_rows.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

fs::path spillway_dir() { return pdp_test::source_dir().parent_path() / "shared" / "data" / "felder-stepped-spillway"; }

// The real profile's rows 01 (AWCC insufficient), 04, 07 and 10, and 10 by
// FSCC alone, at positions not in increasing order.
struct Profile {
  std::vector<awcc::ProcessResult> results;
  std::vector<double> positions{0.002, 0.020, 0.038, 0.054, 0.044};
};

const Profile& profile() {
  static const Profile p = [] {
    Profile out;
    awcc::ProcessOptions o;
    o.reader.fs = 20e3;
    o.dx = 7.15e-3;
    for (const int i : {1, 4, 7, 10}) {
      out.results.push_back(awcc::process_recording(spillway_dir() / fmt::format("dc157_{:02d}.dat", i), o));
    }
    auto fscc_only = o;
    fscc_only.awcc = false;
    out.results.push_back(awcc::process_recording(spillway_dir() / "dc157_10.dat", fscc_only));
    return out;
  }();
  return p;
}

void near(double got, double expected, double relative, const std::string& what) {
  EXPECT_LE(std::abs(got - expected), relative * std::abs(expected)) << what << ": " << got << " vs " << expected;
}

void near(const awcc::Interval95& got, const awcc::Interval95& expected, double relative, const std::string& what) {
  near(got.lower, expected.lower, relative, what + " lower");
  near(got.upper, expected.upper, relative, what + " upper");
}

// Two rows agree: exactly (relative 0) or to `relative`.
void same_row(const correction::ProfileRowOf& got, const correction::ProfileRowOf& expected, double relative,
              const std::string& what) {
  const auto &a = got.row, &b = expected.row;
  EXPECT_EQ(a.name, b.name) << what;
  EXPECT_EQ(got.note, expected.note) << what;
  near(a.y, b.y, relative, what + " y");
  near(a.c, b.c, relative, what + " c");
  near(a.c_ci95, b.c_ci95, relative, what + " c_ci95");
  near(a.bubble_frequency, b.bubble_frequency, relative, what + " F");
  near(a.bubble_frequency_ci95, b.bubble_frequency_ci95, relative, what + " F_ci95");
  ASSERT_EQ(a.u.has_value(), b.u.has_value()) << what;
  if (!b.u) return;
  EXPECT_EQ(a.u_source, b.u_source) << what;
  near(*a.u, *b.u, relative, what + " u");
  ASSERT_EQ(a.u_ci95.has_value(), b.u_ci95.has_value()) << what;
  if (b.u_ci95) near(*a.u_ci95, *b.u_ci95, relative, what + " u_ci95");
  ASSERT_EQ(a.u_sampling_ci95.has_value(), b.u_sampling_ci95.has_value()) << what;
  if (b.u_sampling_ci95) near(*a.u_sampling_ci95, *b.u_sampling_ci95, relative, what + " u_sampling_ci95");
  ASSERT_EQ(a.u_quantiles.size(), b.u_quantiles.size()) << what;
  for (std::size_t k = 0; k < b.u_quantiles.size(); ++k) {
    EXPECT_EQ(a.u_quantiles[k].probability, b.u_quantiles[k].probability) << what;
    near(a.u_quantiles[k].value, b.u_quantiles[k].value, relative, what + " u quantile");
  }
}

// Every number of the flow's JSON within `relative` of the other's; texts equal.
void same_json(const json& got, const json& expected, double relative, const std::string& at) {
  ASSERT_EQ(got.type(), expected.type()) << at;
  if (expected.is_object()) {
    ASSERT_EQ(got.size(), expected.size()) << at;
    for (const auto& [k, v] : expected.items()) same_json(got.at(k), v, relative, at + "/" + k);
  } else if (expected.is_array()) {
    ASSERT_EQ(got.size(), expected.size()) << at;
    for (std::size_t i = 0; i < expected.size(); ++i) same_json(got[i], expected[i], relative, fmt::format("{}/{}", at, i));
  } else if (expected.is_number_float()) {
    near(got.get<double>(), expected.get<double>(), relative, at);
  } else if (expected.is_string() && at.find("notes") == std::string::npos) {
    EXPECT_EQ(got, expected) << at;
  }
}

TEST(ProfileRows, RowsReadBackFromJsonAndCsvAreTheResultsRows) {
  if (!fs::exists(spillway_dir())) GTEST_SKIP() << "the real recordings are not at " << spillway_dir();
  const auto& p = profile();
  const auto model = correction::CorrectionModel::load(pdp_test::source_dir() / "samples" / "model" / "awcc.qrf");
  std::set<awcc::FlowVelocitySource> sources;
  for (const bool corrected : {false, true}) {
    std::vector<correction::Correction> corrections;
    json j{{"profile", json::array()}};
    std::string csv = awcc::profile_csv_header() + (corrected ? "," + correction::correction_csv_header() : "") + "\n";
    std::vector<correction::ProfileRowOf> in_memory;
    for (std::size_t i = 0; i < p.results.size(); ++i) {
      const auto& r = p.results[i];
      if (corrected) corrections.push_back(model.correct(correction::measurement_of(r)));
      const auto* c = corrected ? &corrections.back() : nullptr;
      in_memory.push_back(correction::profile_row(r, p.positions[i], c));
      if (in_memory.back().row.u) sources.insert(in_memory.back().row.u_source);
      auto row = awcc::to_json(r);
      row["position"] = p.positions[i];
      if (c) row["correction"] = correction::to_json(*c);
      j["profile"].push_back(row);
      csv += awcc::profile_csv_row(r, p.positions[i]) + (c ? "," + correction::correction_csv_cells(*c) : "") + "\n";
    }
    const auto from_json = correction::profile_rows_of_json(json::parse(j.dump()), "p.json");
    const auto from_csv = correction::profile_rows_of_csv(csv, "p.csv");
    ASSERT_EQ(from_json.why_none, "");
    ASSERT_EQ(from_csv.why_none, "");
    ASSERT_EQ(from_json.rows.size(), in_memory.size());
    ASSERT_EQ(from_csv.rows.size(), in_memory.size());
    for (std::size_t i = 0; i < in_memory.size(); ++i) {
      same_row(from_json.rows[i], in_memory[i], 0.0, fmt::format("JSON row {} (corrected {})", i, corrected));
      same_row(from_csv.rows[i], in_memory[i], 5e-10, fmt::format("CSV row {} (corrected {})", i, corrected));
    }
    awcc::ProfileFlowOptions o;
    o.draws = 400;
    o.discharge = 0.2;
    const auto expected = awcc::to_json(correction::profile_flow_of(in_memory, o));
    EXPECT_EQ(awcc::to_json(correction::profile_flow_of(from_json.rows, o)), expected);
    same_json(awcc::to_json(correction::profile_flow_of(from_csv.rows, o)), expected, 1e-7, "flow");
  }
  // The rows cover every velocity the rule chooses.
  EXPECT_EQ(sources, (std::set<awcc::FlowVelocitySource>{awcc::FlowVelocitySource::corrected_awcc,
                                                         awcc::FlowVelocitySource::awcc,
                                                         awcc::FlowVelocitySource::fscc}));
}

// The rule of a corrected row the profile leans on (the header): the
// corrected 95 % interval [q_2.5, q_97.5] must meet FSCC's 95 % sampling
// interval. Here the quantiles span [2.0, 2.4]; FSCC's interval is moved
// across the limit on either side.
correction::RowFields corrected_fields(awcc::Interval95 fscc_ci95, bool awcc_low) {
  correction::RowFields f;
  f.name = "r.dat";
  f.position = 0.01;
  f.c = 0.2;
  f.c_ci95 = {0.19, 0.21};
  f.bubble_frequency = 100;
  f.bubble_frequency_ci95 = {90, 110};
  auto& v = f.velocities;
  v.source = awcc_low ? awcc::VelocitySource::fscc : awcc::VelocitySource::awcc;
  v.awcc = 2.6;
  v.awcc_ci95 = {2.55, 2.65};
  v.fscc = 0.5 * (fscc_ci95.lower + fscc_ci95.upper);
  v.fscc_ci95 = fscc_ci95;
  correction::RowVelocities::Corrected c;
  c.corrected = true;
  c.forest = "awcc";
  c.velocity = std::array<double, 9>{2.0, 2.03, 2.05, 2.1, 2.2, 2.3, 2.35, 2.37, 2.4};
  c.awcc_ci95 = v.awcc_ci95;
  c.fscc = v.fscc;
  c.fscc_ci95 = fscc_ci95;
  v.correction = c;
  return f;
}

TEST(ProfileRows, ACorrectedIntervalThatExcludesFsccsIsNotLeanedOn) {
  using awcc::FlowVelocitySource;
  // Meeting at one point, above and below: leaned on, with AWCC's sampling interval as its own part.
  for (const auto ci : {awcc::Interval95{2.4, 2.6}, awcc::Interval95{1.8, 2.0}, awcc::Interval95{2.1, 2.2}}) {
    const auto r = correction::profile_row(corrected_fields(ci, false));
    EXPECT_EQ(r.row.u_source, FlowVelocitySource::corrected_awcc) << ci.lower;
    EXPECT_EQ(*r.row.u, 2.2);
    ASSERT_TRUE(r.row.u_sampling_ci95);
    EXPECT_EQ(r.row.u_sampling_ci95->lower, 2.55);
    EXPECT_EQ(r.note, "");
  }
  // Just beyond on either side: the uncorrected velocity (AWCC of quality ok here), a note naming both.
  for (const auto ci : {awcc::Interval95{2.4000001, 2.6}, awcc::Interval95{1.8, 1.9999999}}) {
    const auto r = correction::profile_row(corrected_fields(ci, false));
    EXPECT_EQ(r.row.u_source, FlowVelocitySource::awcc) << ci.lower;
    EXPECT_EQ(*r.row.u, 2.6);
    EXPECT_TRUE(r.row.u_quantiles.empty());
    EXPECT_NE(r.note.find("corrected AWCC velocity 2.200 m/s (95 % 2.000-2.400) excludes FSCC's"), std::string::npos)
        << r.note;
  }
  // AWCC's low quality alone does not demote the corrected velocity; with the exclusion the row takes FSCC's.
  EXPECT_EQ(correction::profile_row(corrected_fields({2.1, 2.2}, true)).row.u_source,
            FlowVelocitySource::corrected_awcc);
  const auto fscc = correction::profile_row(corrected_fields({2.5, 2.7}, true));
  EXPECT_EQ(fscc.row.u_source, FlowVelocitySource::fscc);
  EXPECT_EQ(*fscc.row.u, 2.6);
  // Without FSCC's interval there is nothing to exclude: leaned on.
  auto no_fscc = corrected_fields({2.5, 2.7}, false);
  no_fscc.velocities.correction->fscc_ci95.reset();
  EXPECT_EQ(correction::profile_row(no_fscc).row.u_source, FlowVelocitySource::corrected_awcc);
}

// The real 8 mm row (issue 53): the corrected AWCC median from 10 windows
// lies far below FSCC and Felder's program; the profile does not lean on it.
TEST(ProfileRows, TheRealEightMillimetreRowContributesItsUncorrectedVelocity) {
  if (!fs::exists(spillway_dir())) GTEST_SKIP() << "the real recordings are not at " << spillway_dir();
  awcc::ProcessOptions o;
  o.reader.fs = 20e3;
  o.dx = 7.15e-3;
  const auto r = awcc::process_recording(spillway_dir() / "dc157_02.dat", o);
  const auto model = correction::CorrectionModel::load(pdp_test::source_dir() / "samples" / "model" / "awcc.qrf");
  const auto c = model.correct(correction::measurement_of(r));
  ASSERT_TRUE(c.corrected() && c.forest == "awcc" && c.velocity) << c.message;
  ASSERT_TRUE(r.fscc && r.fscc->ok() && r.fscc->velocity_ci95);
  ASSERT_LT(c.velocity->quantiles.back(), r.fscc->velocity_ci95->lower);
  const auto row = correction::profile_row(r, 0.008, &c);
  EXPECT_NE(row.row.u_source, awcc::FlowVelocitySource::corrected_awcc);
  EXPECT_EQ(*row.row.u, *r.velocity());
  EXPECT_NE(row.note.find("dc157_02.dat: the corrected AWCC velocity"), std::string::npos) << row.note;
}

TEST(ProfileRows, AFileWithoutEveryPositionHasNoFlowAndSaysWhy) {
  if (!fs::exists(spillway_dir())) GTEST_SKIP() << "the real recordings are not at " << spillway_dir();
  const auto& p = profile();
  json j{{"profile", {awcc::to_json(p.results[1]), awcc::to_json(p.results[2])}}};
  j["profile"][0]["position"] = 0.01;
  j["profile"][1]["position"] = nullptr;
  const auto read = correction::profile_rows_of_json(j, "p.json");
  EXPECT_TRUE(read.rows.empty());
  EXPECT_NE(read.why_none.find("/profile/1 has no position"), std::string::npos) << read.why_none;
  const auto one = correction::profile_rows_of_json(awcc::to_json(p.results[1]), "r.json");
  EXPECT_NE(one.why_none.find("one recording"), std::string::npos) << one.why_none;
  const auto csv = awcc::profile_csv_header() + "\n" + awcc::profile_csv_row(p.results[1], std::nullopt) + "\n";
  EXPECT_NE(correction::profile_rows_of_csv(csv, "p.csv").why_none.find("line 2 has no position"), std::string::npos);
}

}  // namespace
