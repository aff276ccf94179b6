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
