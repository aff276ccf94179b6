// pdp correct's reading of the process JSON and the profile CSV
// (correction/rows.hpp): a file's row is corrected exactly as the result in
// memory it was written from (model.correct(measurement_of(result))), for
// every AWCC outcome of real recordings; an unknown enum text is refused
// naming the file, the row and the value; a JSON written before "status"
// (only "defined") still reads.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/process.hpp"
#include "awcc/serialise.hpp"
#include "correction/features.hpp"
#include "correction/model.hpp"
#include "correction/rows.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

fs::path data_dir() { return pdp_test::source_dir().parent_path() / "shared" / "data" / "felder-stepped-spillway"; }

const correction::CorrectionModel& shipped() {
  static const auto m = correction::CorrectionModel::load(pdp_test::source_dir() / "samples" / "model" / "awcc.qrf");
  return m;
}

// Results of every AWCC outcome the correction tells apart: insufficient
// (file 01), ok (04, 10), bubble-probe corrected, not run.
std::vector<awcc::ProcessResult> results() {
  awcc::ProcessOptions o;
  o.reader.fs = 20e3;
  o.dx = 7.15e-3;
  std::vector<awcc::ProcessResult> out;
  for (const int i : {1, 4, 10}) out.push_back(awcc::process_recording(data_dir() / fmt::format("dc157_{:02d}.dat", i), o));
  auto probe = o;
  probe.awcc_options.probe_correction.enabled = true;
  out.push_back(awcc::process_recording(data_dir() / "dc157_04.dat", probe));
  auto fscc_only = o;
  fscc_only.awcc = false;
  out.push_back(awcc::process_recording(data_dir() / "dc157_10.dat", fscc_only));
  return out;
}

// The last n cells of two CSV lines agree: text exactly, numbers to 1e-8
// (the CSV's 10 digits move a feature in its last digit, and the correction
// with it; a status, forest or a missing value must not move).
void same_cells(const std::string& got, const std::string& expected, std::size_t n, std::size_t row) {
  const auto a = awcc::split_cells(got), b = awcc::split_cells(expected);
  ASSERT_GE(a.size(), n);
  ASSERT_GE(b.size(), n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto& x = a[a.size() - n + k];
    const auto& y = b[b.size() - n + k];
    const auto u = awcc::cell_number(x), v = awcc::cell_number(y);
    if (u && v) {
      EXPECT_NEAR(*u, *v, 1e-8 * std::abs(*v)) << "CSV row " << row << ", correction cell " << k;
    } else {
      EXPECT_EQ(x, y) << "CSV row " << row << ", correction cell " << k;
    }
  }
}

TEST(Rows, FilesAreCorrectedAsTheResultsInMemory) {
  if (!fs::exists(data_dir())) GTEST_SKIP() << "the real recordings are not at " << data_dir();
  const auto& model = shipped();
  const auto rs = results();
  std::vector<correction::CorrectionStatus> statuses;
  json profile{{"profile", json::array()}};
  std::string csv = awcc::profile_csv_header() + "\n";
  for (const auto& r : rs) {
    profile["profile"].push_back(awcc::to_json(r));
    csv += awcc::profile_csv_row(r, 0.01) + "\n";
  }
  const auto from_json = correction::correct_process_json(model, profile.dump(), {}, "p.json", "awcc.qrf");
  const auto from_csv = correction::correct_profile_csv(model, csv, {}, "p.csv");
  const auto corrected_json = json::parse(from_json.text)["profile"];
  std::vector<std::string> lines;
  for (std::size_t start = 0, end; (end = from_csv.text.find('\n', start)) != std::string::npos; start = end + 1) {
    lines.push_back(from_csv.text.substr(start, end - start));
  }
  ASSERT_EQ(lines.size(), rs.size() + 1);
  const std::size_t n = correction::correction_csv_columns().size();
  for (std::size_t i = 0; i < rs.size(); ++i) {
    const auto expected = model.correct(correction::measurement_of(rs[i]));
    statuses.push_back(expected.status);
    auto expected_json = correction::to_json(expected);
    expected_json["model"] = "awcc.qrf";
    EXPECT_EQ(corrected_json[i]["correction"], expected_json) << "JSON row " << i;
    same_cells(lines[i + 1], "x," + correction::correction_csv_cells(expected), n, i);
    // The measurement read from the JSON is the one in memory, feature for feature.
    const auto read = correction::measurement_of_json(awcc::to_json(rs[i]), {}, "p.json");
    const auto in_memory = correction::measurement_of(rs[i]);
    EXPECT_EQ(read.status, in_memory.status) << i;
    EXPECT_EQ(read.measurement.velocity, in_memory.measurement.velocity) << i;
    EXPECT_EQ(read.measurement.fscc_velocity, in_memory.measurement.fscc_velocity) << i;
    EXPECT_EQ(read.measurement.windows_total, in_memory.measurement.windows_total) << i;
    // The time-scale feature too: the JSON's awcc.time_scale_ratio, and the
    // CSV's awcc_time_scale_ratio cell that the CSV reader takes.
    EXPECT_EQ(read.measurement.time_scale_ratio, in_memory.measurement.time_scale_ratio) << i;
    // Chanson's Tu (the +chanson feature): known wherever FSCC gave a
    // velocity, 0 where the JSON states it null (undefined), not known where
    // the JSON does not state it (an earlier pdp's, another writer's).
    EXPECT_EQ(read.measurement.tu_chanson, in_memory.measurement.tu_chanson) << i;
    EXPECT_EQ(in_memory.measurement.tu_chanson.has_value(), in_memory.measurement.fscc_velocity.has_value()) << i;
    if (in_memory.measurement.fscc_velocity) {
      auto j = awcc::to_json(rs[i]);
      j["fscc"]["turbulence_intensity_chanson"] = nullptr;
      EXPECT_EQ(correction::measurement_of_json(j, {}, "p.json").measurement.tu_chanson, 0.0) << i;
      j["fscc"].erase("turbulence_intensity_chanson");
      EXPECT_FALSE(correction::measurement_of_json(j, {}, "p.json").measurement.tu_chanson) << i;
    }
    EXPECT_EQ(in_memory.measurement.time_scale_ratio.has_value(), in_memory.measurement.velocity.has_value()) << i;
    const auto names = awcc::split_cells(awcc::profile_csv_header());
    const auto cells = awcc::split_cells(awcc::profile_csv_row(rs[i], 0.01));
    const auto at = std::find(names.begin(), names.end(), "awcc_time_scale_ratio") - names.begin();
    ASSERT_LT(static_cast<std::size_t>(at), names.size());
    const auto cell = awcc::cell_number(cells[static_cast<std::size_t>(at)]);
    ASSERT_EQ(cell.has_value(), rs[i].awcc && rs[i].awcc->time_scale_ratio.has_value()) << i;
    if (cell) {
      EXPECT_NEAR(*cell, *rs[i].awcc->time_scale_ratio, 1e-9 * *cell) << i;
    }
  }
  // The rows cover what the correction tells apart: the probe-corrected row
  // is refused (a profile CSV's "on" was once not read as corrected).
  EXPECT_EQ(statuses[3], correction::CorrectionStatus::probe_corrected);
  EXPECT_EQ(statuses[1], correction::CorrectionStatus::corrected);
}

template <class Fn>
std::string refusal(Fn&& fn) {
  try {
    fn();
  } catch (const awcc::InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return {};
}

TEST(Rows, UnknownEnumTextIsRefusedNamingFileRowAndValue) {
  if (!fs::exists(data_dir())) GTEST_SKIP() << "the real recordings are not at " << data_dir();
  const auto& model = shipped();
  const auto rs = results();
  // JSON: the second recording's AWCC status and weighting.
  json profile{{"profile", {awcc::to_json(rs[1]), awcc::to_json(rs[2])}}};
  profile["profile"][1]["awcc"]["status"] = "mostly_ok";
  auto m = refusal([&] { correction::correct_process_json(model, profile.dump(), {}, "p.json", "awcc.qrf"); });
  for (const char* part : {"p.json", "/profile/1/awcc", "status", "'mostly_ok'"}) {
    EXPECT_NE(m.find(part), std::string::npos) << m << " lacks " << part;
  }
  profile["profile"][1]["awcc"]["status"] = "ok";
  profile["profile"][1]["awcc"]["options"]["weighting"] = "uniform";
  m = refusal([&] { correction::correct_process_json(model, profile.dump(), {}, "p.json", "awcc.qrf"); });
  for (const char* part : {"p.json", "/profile/1/awcc/options", "weighting", "'uniform'"}) {
    EXPECT_NE(m.find(part), std::string::npos) << m << " lacks " << part;
  }
  // CSV: line 3's signal and line 2's probe flag.
  const std::string header = awcc::profile_csv_header();
  const auto columns = awcc::split_cells(header);
  auto with = [&](const awcc::ProcessResult& r, const std::string& column, const std::string& value) {
    auto cells = awcc::split_cells(awcc::profile_csv_row(r, 0.01));
    for (std::size_t k = 0; k < columns.size(); ++k) {
      if (columns[k] == column) cells[k] = value;
    }
    std::string line;
    for (const auto& c : cells) line += (line.empty() ? "" : ",") + awcc::csv_cell(c);
    return line;
  };
  const std::string good = awcc::profile_csv_row(rs[2], 0.01);
  m = refusal([&] {
    correction::correct_profile_csv(model, header + "\n" + good + "\n" + with(rs[1], "awcc_signal", "voltage") + "\n", {},
                                    "p.csv");
  });
  for (const char* part : {"p.csv", "line 3", "awcc_signal", "'voltage'"}) {
    EXPECT_NE(m.find(part), std::string::npos) << m << " lacks " << part;
  }
  m = refusal([&] {
    correction::correct_profile_csv(model, header + "\n" + with(rs[1], "awcc_probe_corrected", "yes") + "\n", {},
                                    "p.csv");
  });
  for (const char* part : {"p.csv", "line 2", "awcc_probe_corrected", "'yes'"}) {
    EXPECT_NE(m.find(part), std::string::npos) << m << " lacks " << part;
  }
}

TEST(Rows, AJsonWrittenBeforeStatusReadsItsDefinedKey) {
  if (!fs::exists(data_dir())) GTEST_SKIP() << "the real recordings are not at " << data_dir();
  const auto rs = results();
  for (const std::size_t i : {std::size_t{0}, std::size_t{1}}) {  // AWCC insufficient, AWCC ok
    json j = awcc::to_json(rs[i]);
    const auto now = correction::measurement_of_json(j, {}, "new.json");
    for (const char* method : {"awcc", "fscc"}) {
      j[method]["defined"] = j[method]["status"] == "ok";
      j[method].erase("status");
    }
    const auto old = correction::measurement_of_json(j, {}, "old.json");
    EXPECT_EQ(old.status, now.status) << i;
    EXPECT_EQ(old.measurement.velocity, now.measurement.velocity) << i;
    EXPECT_EQ(old.measurement.fscc_velocity, now.measurement.fscc_velocity) << i;
    // Neither key: refused, not read as a default.
    j["awcc"].erase("defined");
    const auto m = refusal([&] { correction::measurement_of_json(j, {}, "old.json", "/profile/7"); });
    EXPECT_NE(m.find("/profile/7/awcc"), std::string::npos) << m;
  }
}

}  // namespace

// The header every CSV reader of the correction reads by (awcc/csv.hpp): a
// Windows line end is not part of the last name, a quoted name loses its
// quotes, and of a name given twice the last column is the one read.
TEST(CsvHeader, NamesTheirColumnsWithoutTheLineEnd) {
  const auto h = awcc::csv_header("file,\"a,b\",u,u\r");
  ASSERT_EQ(h.names.size(), 4u);
  EXPECT_EQ(h.names[1], "a,b");
  EXPECT_EQ(h.names[3], "u");
  EXPECT_EQ(h.index.at("a,b"), 1u);
  EXPECT_EQ(h.index.at("u"), 3u);
  EXPECT_EQ(h.index.count("u\r"), 0u);
  EXPECT_TRUE(awcc::csv_header("").index.count(""));
}
