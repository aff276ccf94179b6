// The profile CSV's column declarations (awcc::profile_csv_columns) against
// the rows profile_csv_row writes: every cell equals the JSON value at the
// column's pointer, for the real recordings and for synthetic ones whose AWCC
// is ok, insufficient or not run. The report's table reads the JSON through
// these pointers, so a wrong pointer here would put a wrong number there.
#include <gtest/gtest.h>

#include <filesystem>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "awcc/csv.hpp"
#include "awcc/process.hpp"
#include "awcc/serialise.hpp"
#include "synth/recording.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The text a JSON value has in the CSV, by the rules the declaration states.
std::string as_cell(const std::string& column, const json& v) {
  if (v.is_null()) return "";
  if (v.is_boolean()) {
    if (column == "correction_in_range") return v.get<bool>() ? "1" : "0";
    return v.get<bool>() ? "on" : "off";
  }
  if (v.is_array()) {
    std::string out;
    for (const auto& w : v) out += (out.empty() ? "" : "; ") + w.get<std::string>();
    return out;
  }
  if (v.is_number()) return awcc::csv_number(v.get<double>());
  return v.get<std::string>();
}

void check_row(const awcc::ProcessResult& r, const std::optional<double>& position, const std::string& what) {
  json j = awcc::to_json(r);
  j["position"] = position ? json(*position) : json(nullptr);
  // The CSV names the file only; the JSON holds the path the user gave.
  j["file"] = fs::path(j["file"].get<std::string>()).filename().string();
  const auto cells = awcc::split_cells(awcc::profile_csv_row(r, position));
  const auto columns = awcc::profile_csv_columns();
  ASSERT_EQ(cells.size(), columns.size()) << what;
  int compared = 0;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const auto& c = columns[k];
    if (c.json_pointer.empty()) continue;  // the version: in the provenance
    const json::json_pointer p{std::string(c.json_pointer)};
    const json value = j.contains(p) ? j.at(p) : json(nullptr);
    EXPECT_EQ(cells[k], as_cell(std::string(c.name), value)) << what << ": column " << c.name << " at " << c.json_pointer;
    // A number has a unit ("-" when dimensionless); text, a flag or a list has none.
    if (value.is_number()) {
      EXPECT_FALSE(c.unit.empty()) << c.name;
    } else if (!value.is_null()) {
      EXPECT_TRUE(c.unit.empty()) << c.name;
    }
    ++compared;
  }
  EXPECT_EQ(compared + 1, static_cast<int>(columns.size()));
}

TEST(ProfileColumns, HeaderIsTheDeclaredNamesWithUnits) {
  const auto cells = awcc::split_cells(awcc::profile_csv_header());
  const auto columns = awcc::profile_csv_columns();
  ASSERT_EQ(cells.size(), columns.size());
  for (std::size_t k = 0; k < columns.size(); ++k) {
    EXPECT_EQ(cells[k], columns[k].name);
    EXPECT_FALSE(columns[k].meaning.empty()) << columns[k].name;
  }
}

TEST(ProfileColumns, EveryCellEqualsTheJsonAtItsPointerOnSyntheticRecordings) {
  synth::Scene s;
  s.duration = 4.0;
  s.fs = 100e3;
  s.dy = 0.0;
  const auto syn = synth::synthesise(s);
  const auto path = pdp_test::test_file("scene.flac");
  synth::write_recording(path, s, syn.signals, {});

  awcc::ProcessOptions o;
  o.dx = s.dx;
  const auto both = awcc::process_recording(path, o);
  ASSERT_TRUE(both.awcc && both.awcc->ok()) << both.awcc->message;
  check_row(both, 0.012, "AWCC ok");

  // Windows of 1000 particles: fewer than 10 windows in 4 s, AWCC insufficient.
  o.awcc_options.np = 1000;
  const auto insufficient = awcc::process_recording(path, o);
  ASSERT_TRUE(insufficient.awcc && !insufficient.awcc->ok()) << insufficient.awcc->windows_total;
  check_row(insufficient, std::nullopt, "AWCC insufficient");

  o.awcc_options.np = 10;
  o.awcc = false;
  const auto fscc_only = awcc::process_recording(path, o);
  ASSERT_FALSE(fscc_only.awcc);
  check_row(fscc_only, 0.0, "FSCC only");

  o.dx = 0.0;  // no velocity at all
  o.fscc = true;
  const auto no_dx = awcc::process_recording(path, o);
  check_row(no_dx, 1e-3, "no dx");
}

TEST(ProfileColumns, EveryCellEqualsTheJsonAtItsPointerOnTheRealRecordings) {
  const auto dir = pdp_test::source_dir().parent_path() / "shared" / "data" / "felder-stepped-spillway";
  if (!fs::exists(dir)) GTEST_SKIP() << "the real recordings are not at " << dir << " (../shared/data beside the repo)";
  awcc::ProcessOptions o;
  o.reader.fs = 20e3;
  o.dx = 7.15e-3;
  for (int i = 1; i <= 10; ++i) {
    const auto file = dir / fmt::format("dc157_{:02d}.dat", i);
    check_row(awcc::process_recording(file, o), 0.002 + 0.006 * (i - 1), file.filename().string());
  }
}

}  // namespace
