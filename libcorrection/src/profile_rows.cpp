#include "correction/profile_rows.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <map>
#include <sstream>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/read_back.hpp"

namespace correction {

ProfileRowOf profile_row(const RowFields& f) {
  ProfileRowOf out;
  auto& row = out.row;
  row.name = f.name;
  row.y = f.position;
  row.c = f.c;
  row.c_ci95 = f.c_ci95;
  row.bubble_frequency = f.bubble_frequency;
  row.bubble_frequency_ci95 = f.bubble_frequency_ci95;
  const auto& v = f.velocities;
  if (v.correction && v.correction->corrected && v.correction->forest == "awcc" && v.correction->velocity) {
    const auto& c = *v.correction;
    const auto& q = *c.velocity;  // at correction_levels: front and back 2.5 and 97.5 %
    if (!(c.fscc && c.fscc_ci95 && (q.back() < c.fscc_ci95->lower || q.front() > c.fscc_ci95->upper))) {
      row.u = q[median_level];
      row.u_source = awcc::FlowVelocitySource::corrected_awcc;
      for (std::size_t i = 0; i < correction_levels.size(); ++i) row.u_quantiles.push_back({correction_levels[i], q[i]});
      row.u_sampling_ci95 = c.awcc_ci95;
      return out;
    }
    out.note = fmt::format("{}: the corrected AWCC velocity {:.3f} m/s (95 % {:.3f}-{:.3f}) excludes FSCC's {:.3f} "
                           "m/s (95 % {:.3f}-{:.3f}): the methods disagree beyond their uncertainty, so the row "
                           "contributes its uncorrected velocity (METHOD 12 as docs/validation.md decides it)",
                           row.name, q[median_level], q.front(), q.back(), *c.fscc, c.fscc_ci95->lower, c.fscc_ci95->upper);
  }
  switch (v.source) {
    case awcc::VelocitySource::awcc:
      row.u = v.awcc;
      row.u_source = awcc::FlowVelocitySource::awcc;
      row.u_ci95 = v.awcc_ci95;
      break;
    case awcc::VelocitySource::fscc:
      if (v.fscc_ci95) {
        row.u = v.fscc;
        row.u_source = awcc::FlowVelocitySource::fscc;
        row.u_ci95 = *v.fscc_ci95;
      } else {
        out.note = fmt::format("{}: FSCC's velocity {:.3f} m/s has no sampling interval (too few segments hold a "
                               "peak): left out of the discharge",
                               row.name, v.fscc);
      }
      break;
    case awcc::VelocitySource::none:
      out.note = fmt::format("{}: no velocity (neither AWCC nor FSCC gave one)", row.name);
      break;
  }
  return out;
}

RowFields row_fields(const awcc::ProcessResult& r, double position, const Correction* correction) {
  RowFields f;
  f.name = r.info.path.filename().string();
  f.position = position;
  const auto& lead = r.tips.at(0).phase;
  f.c = lead.void_fraction;
  f.c_ci95 = lead.void_fraction_ci95;
  f.bubble_frequency = lead.bubble_count_rate;
  f.bubble_frequency_ci95 = lead.bubble_count_rate_ci95;
  auto& v = f.velocities;
  v.source = r.velocity_source();
  if (v.source == awcc::VelocitySource::awcc) {
    v.awcc = r.awcc->velocity;
    v.awcc_ci95 = r.awcc->velocity_ci95;
  } else if (v.source == awcc::VelocitySource::fscc) {
    v.fscc = r.fscc->velocity;
    v.fscc_ci95 = r.fscc->velocity_ci95;
  }
  if (correction) {
    RowVelocities::Corrected c;
    c.corrected = correction->corrected();
    c.forest = correction->forest;
    if (correction->velocity) c.velocity = correction->velocity->quantiles;
    if (r.awcc && r.awcc->ok()) c.awcc_ci95 = r.awcc->velocity_ci95;
    if (r.fscc && r.fscc->ok()) {
      c.fscc = r.fscc->velocity;
      c.fscc_ci95 = r.fscc->velocity_ci95;
    }
    v.correction = std::move(c);
  }
  return f;
}

ProfileRowOf profile_row(const awcc::ProcessResult& result, double position, const Correction* correction) {
  return profile_row(row_fields(result, position, correction));
}

awcc::ProfileFlowResult profile_flow_of(std::vector<ProfileRowOf> rows, const awcc::ProfileFlowOptions& options) {
  std::vector<awcc::ProfileRow> plain;
  std::vector<std::string> notes;
  for (auto& r : rows) {
    if (!r.note.empty()) notes.push_back(std::move(r.note));
    plain.push_back(std::move(r.row));
  }
  auto flow = awcc::profile_flow(std::move(plain), options);
  flow.notes.insert(flow.notes.end(), notes.begin(), notes.end());
  flow.alerts.insert(flow.alerts.end(), notes.begin(), notes.end());
  return flow;
}

namespace {

using nlohmann::json;
namespace key = awcc::process_key;
namespace column = awcc::profile_column;

// --- the process JSON -------------------------------------------------------

// A value of entry `at` (its JSON pointer) that the row needs, or the file is
// refused naming where.
struct JsonEntry {
  const std::string& file;
  std::string at;

  [[noreturn]] void refuse(std::string_view k, std::string_view what) const {
    throw awcc::InputError(fmt::format("{}: {}: no {} '{}'; give a JSON written by pdp process", file, at, what, k));
  }
  const json& object(const json& j, std::string_view k) const {
    if (!j.is_object() || !j.contains(k) || !j[k].is_object()) refuse(k, "object");
    return j[k];
  }
  double number(const json& j, std::string_view k) const {
    if (!j.is_object() || !j.contains(k) || !j[k].is_number()) refuse(k, "number");
    return j[k].get<double>();
  }
  std::string text(const json& j, std::string_view k) const {
    if (!j.is_object() || !j.contains(k) || !j[k].is_string()) refuse(k, "text");
    return j[k].get<std::string>();
  }
  awcc::Interval95 interval(const json& j, std::string_view k) const {
    const auto i = optional_interval(j, k);
    if (!i) refuse(k, "interval [lower, upper]");
    return *i;
  }
  // null or absent: none; anything but two numbers: refused.
  std::optional<awcc::Interval95> optional_interval(const json& j, std::string_view k) const {
    if (!j.is_object() || !j.contains(k) || j[k].is_null()) return std::nullopt;
    const auto& a = j[k];
    if (!a.is_array() || a.size() != 2 || !a[0].is_number() || !a[1].is_number()) refuse(k, "interval [lower, upper]");
    return awcc::Interval95{a[0].get<double>(), a[1].get<double>()};
  }
};

RowFields fields_of_json(const json& r, double position, const JsonEntry& e) {
  RowFields f;
  f.name = std::filesystem::path(e.text(r, key::file)).filename().string();
  f.position = position;
  if (!r.contains(key::tips) || !r[key::tips].is_array() || r[key::tips].empty()) e.refuse(key::tips, "list");
  const auto& lead = r[key::tips][0];
  f.c = e.number(lead, key::void_fraction);
  f.c_ci95 = e.interval(lead, key::void_fraction_ci95);
  f.bubble_frequency = e.number(lead, key::bubble_count_rate);
  f.bubble_frequency_ci95 = e.interval(lead, key::bubble_count_rate_ci95);
  auto& v = f.velocities;
  v.source = awcc::parse_velocity_source(e.text(r, key::chord_velocity_source),
                                         {e.file, e.at, key::chord_velocity_source});
  if (v.source == awcc::VelocitySource::awcc) {
    const auto& a = e.object(r, key::awcc);
    v.awcc = e.number(a, key::velocity);
    v.awcc_ci95 = e.interval(a, key::velocity_ci95);
  } else if (v.source == awcc::VelocitySource::fscc) {
    const auto& s = e.object(r, key::fscc);
    v.fscc = e.number(s, key::velocity);
    v.fscc_ci95 = e.optional_interval(s, key::velocity_ci95);
  }
  if (r.contains(correction_key::correction) && !r[correction_key::correction].is_null()) {
    const JsonEntry at{e.file, e.at + "/" + std::string(correction_key::correction)};
    const auto& c = e.object(r, correction_key::correction);
    RowVelocities::Corrected out;
    out.corrected = at.text(c, correction_key::status) == to_string(CorrectionStatus::corrected);
    if (c.contains(correction_key::forest) && !c[correction_key::forest].is_null()) {
      out.forest = at.text(c, correction_key::forest);
    }
    if (c.contains(correction_key::velocity) && !c[correction_key::velocity].is_null()) {
      const JsonEntry u{e.file, at.at + "/" + std::string(correction_key::velocity)};
      const auto& q = u.object(u.object(c, correction_key::velocity), correction_key::quantiles);
      const JsonEntry levels{e.file, u.at + "/" + std::string(correction_key::quantiles)};
      std::array<double, correction_levels.size()> values{};
      for (std::size_t i = 0; i < values.size(); ++i) values[i] = levels.number(q, correction_level_names[i]);
      out.velocity = values;
    }
    if (r.contains(key::awcc) && r[key::awcc].is_object()) {
      const JsonEntry at_awcc{e.file, e.at + "/" + std::string(key::awcc)};
      const auto& a = r[key::awcc];
      if (at_awcc.text(a, key::status) == awcc::to_string(awcc::AwccStatus::ok)) {
        out.awcc_ci95 = at_awcc.optional_interval(a, key::velocity_ci95);
      }
    }
    if (r.contains(key::fscc) && r[key::fscc].is_object()) {
      const JsonEntry at_fscc{e.file, e.at + "/" + std::string(key::fscc)};
      const auto& s = r[key::fscc];
      if (at_fscc.text(s, key::status) == awcc::to_string(awcc::FsccStatus::ok)) {
        out.fscc = at_fscc.number(s, key::velocity);
        out.fscc_ci95 = at_fscc.optional_interval(s, key::velocity_ci95);
      }
    }
    v.correction = std::move(out);
  }
  return f;
}

// --- the profile CSV ---------------------------------------------------------

struct CsvRow {
  const std::map<std::string, std::size_t, std::less<>>& col;
  const std::vector<std::string>& cells;
  const std::string& file;
  std::string line;  ///< "line N"

  [[nodiscard]] std::string text(std::string_view name) const {
    const auto it = col.find(name);
    return it == col.end() ? std::string() : cells[it->second];
  }
  [[nodiscard]] std::optional<double> optional(std::string_view name) const {
    const auto t = text(name);
    if (t.empty()) return std::nullopt;
    const auto v = awcc::cell_number(t);
    if (!v) throw awcc::InputError(fmt::format("{}: {}: column {} = '{}' is not a number", file, line, name, t));
    return v;
  }
  [[nodiscard]] double number(std::string_view name) const {
    const auto v = optional(name);
    if (!v) {
      throw awcc::InputError(fmt::format("{}: {}: column {} is empty; give a profile CSV written by pdp process", file,
                                         line, name));
    }
    return *v;
  }
  [[nodiscard]] std::optional<awcc::Interval95> optional_interval(std::string_view lower, std::string_view upper) const {
    const auto a = optional(lower), b = optional(upper);
    if (!a && !b) return std::nullopt;
    return awcc::Interval95{number(lower), number(upper)};
  }
  [[nodiscard]] awcc::Interval95 interval(std::string_view lower, std::string_view upper) const {
    return {number(lower), number(upper)};
  }
};

RowFields fields_of_csv(const CsvRow& r, double position) {
  RowFields f;
  f.name = r.text(column::file);
  f.position = position;
  f.c = r.number(column::void_fraction);
  f.c_ci95 = r.interval(column::void_fraction_ci95_lower, column::void_fraction_ci95_upper);
  f.bubble_frequency = r.number(column::bubble_count_rate);
  f.bubble_frequency_ci95 = r.interval(column::bubble_count_rate_ci95_lower, column::bubble_count_rate_ci95_upper);
  auto& v = f.velocities;
  v.source = awcc::parse_velocity_source(r.text(column::chord_velocity_source),
                                         {r.file, r.line, column::chord_velocity_source});
  if (v.source == awcc::VelocitySource::awcc) {
    v.awcc = r.number(column::awcc_velocity);
    v.awcc_ci95 = r.interval(column::awcc_velocity_ci95_lower, column::awcc_velocity_ci95_upper);
  } else if (v.source == awcc::VelocitySource::fscc) {
    v.fscc = r.number(column::fscc_velocity);
    v.fscc_ci95 = r.optional_interval(column::fscc_velocity_ci95_lower, column::fscc_velocity_ci95_upper);
  }
  if (r.col.count(correction_column::status)) {
    RowVelocities::Corrected c;
    c.corrected = r.text(correction_column::status) == to_string(CorrectionStatus::corrected);
    c.forest = r.text(correction_column::forest);
    const std::string first = std::string(correction_column::velocity_quantile) + correction_level_names[0];
    if (r.optional(first)) {
      std::array<double, correction_levels.size()> values{};
      for (std::size_t i = 0; i < values.size(); ++i) {
        values[i] = r.number(std::string(correction_column::velocity_quantile) + correction_level_names[i]);
      }
      c.velocity = values;
    }
    if (r.text(column::awcc_status) == awcc::to_string(awcc::AwccStatus::ok)) {
      c.awcc_ci95 = r.optional_interval(column::awcc_velocity_ci95_lower, column::awcc_velocity_ci95_upper);
    }
    if (r.text(column::fscc_status) == awcc::to_string(awcc::FsccStatus::ok)) {
      c.fscc = r.optional(column::fscc_velocity);
      c.fscc_ci95 = r.optional_interval(column::fscc_velocity_ci95_lower, column::fscc_velocity_ci95_upper);
    }
    v.correction = std::move(c);
  }
  return f;
}

}  // namespace

ProfileRowsRead profile_rows_of_json(const nlohmann::json& j, const std::string& file) {
  ProfileRowsRead out;
  if (!j.is_object() || !j.contains(key::profile) || !j[key::profile].is_array()) {
    if (j.is_object() && j.contains(key::tips)) {
      out.why_none = fmt::format("{} holds one recording, not a profile", file);
      return out;
    }
    throw awcc::InputError(
        fmt::format("{}: neither a recording's result (tips) nor a profile; give a JSON written by pdp process", file));
  }
  const auto& rows = j[key::profile];
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const JsonEntry e{file, fmt::format("/{}/{}", key::profile, i)};
    const auto& r = rows[i];
    if (!r.is_object()) e.refuse("", "object");
    if (!r.contains(key::position) || r[key::position].is_null()) {
      out.rows.clear();
      out.why_none = fmt::format("{}: {} has no position (a profile's flow needs every position: give the "
                                 "positions or a manifest)",
                                 file, e.at);
      return out;
    }
    out.rows.push_back(profile_row(fields_of_json(r, e.number(r, key::position), e)));
  }
  return out;
}

ProfileRowsRead profile_rows_of_csv(const std::string& text, const std::string& file) {
  ProfileRowsRead out;
  std::stringstream in(text);
  std::string line;
  if (!std::getline(in, line)) throw awcc::InputError(fmt::format("{}: empty file", file));
  const auto header = awcc::csv_header(line);
  const auto& col = header.index;
  for (const auto name : {column::file, column::position, column::void_fraction, column::void_fraction_ci95_lower,
                          column::bubble_count_rate, column::chord_velocity_source}) {
    if (!col.count(name)) {
      out.why_none = fmt::format("{}: no column '{}': not a profile CSV of pdp process with its intervals "
                                 "(docs/output.md)",
                                 file, name);
      return out;
    }
  }
  for (int number = 2; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = awcc::split_cells(line);
    const CsvRow r{col, cells, file, fmt::format("line {}", number)};
    if (cells.size() != header.names.size()) {
      throw awcc::InputError(fmt::format("{}: {}: {} cells where the header has {}", file, r.line, cells.size(),
                                         header.names.size()));
    }
    const auto position = r.optional(column::position);
    if (!position) {
      out.rows.clear();
      out.why_none = fmt::format("{}: {} has no position (a profile's flow needs every position: give the "
                                 "positions or a manifest)",
                                 file, r.line);
      return out;
    }
    out.rows.push_back(profile_row(fields_of_csv(r, *position)));
  }
  return out;
}

}  // namespace correction
