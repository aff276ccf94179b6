// Reading back what awcc/serialise.hpp writes (awcc/read_back.hpp): every
// enum value's text parses back to the value, a text pdp does not write is
// refused naming the file, the row, the field and the value, and every
// column of the profile CSV of real recordings reads back to the value of the
// result it was written from (the flags column to the row's flags, in order).
#include <gtest/gtest.h>

#include <filesystem>
#include <fmt/format.h>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/process.hpp"
#include "awcc/read_back.hpp"
#include "awcc/serialise.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const awcc::WrittenAt kAt{"dir/run.json", "/profile/3/awcc", "status"};

// Every value of an enum (by its underlying number up to `count`) parses back
// from its text, and the texts are distinct.
template <class E, class Parse>
void every_value_parses_back(int count, Parse parse) {
  std::map<std::string, int> seen;
  for (int k = 0; k < count; ++k) {
    const auto v = static_cast<E>(k);
    const std::string text(awcc::to_string(v));
    EXPECT_TRUE(seen.emplace(text, k).second) << text << " written for two values";
    EXPECT_EQ(parse(text, kAt), v) << text;
  }
}

TEST(ReadBack, EveryEnumValueParsesBackFromItsText) {
  every_value_parses_back<awcc::PhaseStatus>(4, awcc::parse_phase_status);
  every_value_parses_back<awcc::FsccStatus>(9, awcc::parse_fscc_status);
  every_value_parses_back<awcc::AwccStatus>(6, awcc::parse_awcc_status);
  every_value_parses_back<awcc::AwccQuality>(3, awcc::parse_awcc_quality);
  every_value_parses_back<awcc::Weighting>(2, awcc::parse_weighting);
  every_value_parses_back<awcc::CorrelationSignal>(2, awcc::parse_correlation_signal);
  every_value_parses_back<awcc::Subsample>(2, awcc::parse_subsample);
  every_value_parses_back<awcc::WindowFate>(static_cast<int>(awcc::window_fate_count), awcc::parse_window_fate);
  every_value_parses_back<awcc::VelocitySource>(3, awcc::parse_velocity_source);
  every_value_parses_back<awcc::Flag>(static_cast<int>(awcc::flag_names.size()), awcc::parse_flag);
  EXPECT_TRUE(awcc::parse_switch("on", kAt));
  EXPECT_FALSE(awcc::parse_switch("off", kAt));
}

// The message of a refused text names where it was and what it was.
template <class Parse>
void refused(Parse parse, const std::string& text) {
  try {
    parse(text, kAt);
    ADD_FAILURE() << "'" << text << "' accepted";
  } catch (const awcc::InputError& e) {
    const std::string m = e.what();
    for (const char* part : {"dir/run.json", "/profile/3/awcc", "status"}) {
      EXPECT_NE(m.find(part), std::string::npos) << m << " does not name " << part;
    }
    EXPECT_NE(m.find("'" + text + "'"), std::string::npos) << m;
  }
}

TEST(ReadBack, TextPdpDoesNotWriteIsRefusedNamingFileRowAndValue) {
  // Texts that a silent default once turned into a value: another case, an
  // empty cell, a neighbour's value, the old boolean spelling.
  refused(awcc::parse_phase_status, "OK");
  refused(awcc::parse_fscc_status, "");
  refused(awcc::parse_awcc_status, "insufficient");  // a quality, not a status
  refused(awcc::parse_awcc_quality, "too_few_windows");
  refused(awcc::parse_weighting, "uniform");
  refused(awcc::parse_correlation_signal, "voltage");
  refused(awcc::parse_subsample, "cubic");
  refused(awcc::parse_window_fate, "rejected");
  refused(awcc::parse_velocity_source, "both");
  refused(awcc::parse_switch, "true");
  refused(awcc::parse_switch, "1");
  refused(awcc::parse_flag, "E4");  // the warning's name in the paper, not a code pdp writes
}

// The text of the row's cell of a column, by the declaration's name.
std::map<std::string, std::string> cells_by_name(const std::string& row) {
  const auto cells = awcc::split_cells(row);
  const auto columns = awcc::profile_csv_columns();
  EXPECT_EQ(cells.size(), columns.size());
  std::map<std::string, std::string> out;
  for (std::size_t k = 0; k < columns.size() && k < cells.size(); ++k) out[std::string(columns[k].name)] = cells[k];
  return out;
}

// Each column read back by its reader to the value of the result: enums by
// their parsers, switches as on/off, numbers to 10 digits, text as written.
void check_read_back(const awcc::ProcessResult& r, const std::string& what) {
  const auto cell = cells_by_name(awcc::profile_csv_row(r, 0.014));
  const awcc::WrittenAt at{"profile.csv", "line 2", ""};
  json j = awcc::to_json(r);
  j["position"] = 0.014;
  int enums = 0;
  using Check = std::function<void(const std::string&)>;
  const std::map<std::string_view, Check> enum_columns{
      {awcc::profile_column::fscc_status,
       [&](const std::string& t) { EXPECT_EQ(awcc::parse_fscc_status(t, at), r.fscc->status); }},
      {awcc::profile_column::awcc_status,
       [&](const std::string& t) { EXPECT_EQ(awcc::parse_awcc_status(t, at), r.awcc->status); }},
      {awcc::profile_column::awcc_quality,
       [&](const std::string& t) { EXPECT_EQ(awcc::parse_awcc_quality(t, at), r.awcc->quality); }},
      {awcc::profile_column::awcc_weighting,
       [&](const std::string& t) { EXPECT_EQ(awcc::parse_weighting(t, at), r.awcc->options.weighting); }},
      {awcc::profile_column::awcc_signal,
       [&](const std::string& t) { EXPECT_EQ(awcc::parse_correlation_signal(t, at), r.awcc->options.signal); }},
      {awcc::profile_column::awcc_subsample,
       [&](const std::string& t) { EXPECT_EQ(awcc::parse_subsample(t, at), r.awcc->options.subsample); }},
      {awcc::profile_column::awcc_roc,
       [&](const std::string& t) { EXPECT_EQ(awcc::parse_switch(t, at), r.awcc->options.roc); }},
      {awcc::profile_column::awcc_probe_corrected,
       [&](const std::string& t) { EXPECT_EQ(awcc::parse_switch(t, at), r.awcc->probe_corrected); }},
      {awcc::profile_column::chord_velocity_source,
       [&](const std::string& t) { EXPECT_EQ(awcc::parse_velocity_source(t, at), r.velocity_source()); }},
  };
  for (const auto& c : awcc::profile_csv_columns()) {
    const std::string& text = cell.at(std::string(c.name));
    SCOPED_TRACE(what + ": column " + std::string(c.name) + " = '" + text + "'");
    if (c.name == awcc::profile_column::flags) {
      std::vector<awcc::Flag> flags;
      for (const auto& w : r.warnings) flags.push_back(w.flag);
      EXPECT_EQ(awcc::parse_flags_cell(text, at), flags);
      continue;
    }
    if (const auto e = enum_columns.find(c.name); e != enum_columns.end()) {
      if (!text.empty()) {  // empty: the method was not run
        e->second(text);
        ++enums;
      }
      continue;
    }
    if (c.json_pointer.empty()) continue;  // the version: the provenance's
    const json::json_pointer p{std::string(c.json_pointer)};
    const json v = j.contains(p) ? j.at(p) : json(nullptr);
    if (v.is_number()) {
      const auto back = awcc::cell_number(text);
      ASSERT_TRUE(back.has_value());
      EXPECT_NEAR(*back, v.get<double>(), 5e-10 * std::abs(v.get<double>()));
    } else if (v.is_null()) {
      EXPECT_EQ(text, "");
    } else if (v.is_string() && c.name != "file") {
      EXPECT_EQ(awcc::split_cells(awcc::csv_cell(v.get<std::string>()))[0], text);
    }
  }
  // FSCC's and AWCC's columns are there whenever the method ran.
  EXPECT_EQ(enums, (r.fscc ? 1 : 0) + (r.awcc ? 7 : 0) + 1) << what;
}

TEST(ReadBack, EveryProfileColumnReadsBackToTheResultsValueOnRealRecordings) {
  const auto dir = pdp_test::source_dir().parent_path() / "shared" / "data" / "felder-stepped-spillway";
  if (!fs::exists(dir)) GTEST_SKIP() << "the real recordings are not at " << dir << " (../shared/data beside the repo)";
  awcc::ProcessOptions o;
  o.reader.fs = 20e3;
  o.dx = 7.15e-3;
  // File 01: AWCC insufficient; 04 and 10: ok; raw signals, the probe
  // correction and no AWCC give the other values of the enum columns.
  for (const int i : {1, 4, 10}) {
    const auto file = dir / fmt::format("dc157_{:02d}.dat", i);
    check_read_back(awcc::process_recording(file, o), file.filename().string());
  }
  const auto file = dir / "dc157_04.dat";
  auto raw = o;
  raw.awcc_options.signal = awcc::CorrelationSignal::raw;
  raw.awcc_options.weighting = awcc::Weighting::none;
  raw.awcc_options.subsample = awcc::Subsample::parabolic;
  raw.awcc_options.roc = false;
  check_read_back(awcc::process_recording(file, raw), "raw signals");
  auto probe = o;
  probe.awcc_options.probe_correction.enabled = true;
  const auto corrected = awcc::process_recording(file, probe);
  ASSERT_TRUE(corrected.awcc && corrected.awcc->probe_corrected);
  check_read_back(corrected, "probe correction");
  auto fscc_only = o;
  fscc_only.awcc = false;
  check_read_back(awcc::process_recording(file, fscc_only), "FSCC only");
}

}  // namespace
