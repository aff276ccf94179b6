#include "correction/rows.hpp"

#include <fmt/format.h>

#include <cmath>

#include <map>
#include <sstream>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/json_text.hpp"
#include "awcc/read_back.hpp"

namespace correction {

namespace {

using nlohmann::json;

// What a row lacks and the defaults do not give is an error naming the file,
// the quantity and its fix.
double need(const std::optional<double>& from_file, const std::optional<double>& from_default,
            const std::string& where, const char* quantity, const char* what) {
  if (from_file) return *from_file;
  if (from_default) return *from_default;
  throw awcc::OptionError(fmt::format("{}: no {} in the file; state the {}", where, quantity, what), quantity);
}

// A count from a file: a whole number from 0 to 2^53, or the file is refused.
std::int64_t whole(double v, const std::string& where, const char* name) {
  if (!(v >= 0.0 && v <= 9007199254740992.0 && v == std::floor(v))) {
    throw awcc::InputError(fmt::format("{}: {} = {} is not a count (a whole number from 0)", where, name, v));
  }
  return static_cast<std::int64_t>(v);
}

std::optional<double> default_np(const RowDefaults& d) {
  return d.np ? std::optional<double>(*d.np) : std::nullopt;
}

void check_processing(const CorrectionModel& model, const std::optional<Processing>& results, const std::string& where,
                      std::vector<std::string>& warnings) {
  if (!results) {
    warnings.push_back(fmt::format("{}: the file does not record how AWCC was processed; assumed as the model's ({})",
                                   where, describe(model.processing)));
    return;
  }
  if (const auto why = model.mismatch(*results); !why.empty()) {
    throw awcc::InputError(fmt::format("{}: processed differently from the model's training data ({}); reprocess with "
                                       "the model's settings or train a model for these",
                                       where, why));
  }
}

namespace key = awcc::process_key;
namespace column = awcc::profile_column;

bool has(const json& j, std::string_view k) { return j.is_object() && j.contains(k); }

std::optional<double> number(const json& j, std::string_view k) {
  if (!has(j, k) || !j[k].is_number()) return std::nullopt;
  return j[k].get<double>();
}

double required(const json& j, std::string_view k, const std::string& row, const std::string& file) {
  const auto v = number(j, k);
  if (!v) throw awcc::InputError(fmt::format("{}: no number '{}' in {}; give a JSON written by pdp process", file, k, row));
  return *v;
}

// The text of an enum's key, or the file is refused: no key falls back to a default.
std::string text(const json& j, std::string_view k, const std::string& row, const std::string& file) {
  if (!has(j, k) || !j[k].is_string()) {
    throw awcc::InputError(fmt::format("{}: {}: no text '{}'; give a JSON written by pdp process", file, row, k));
  }
  return j[k].get<std::string>();
}

// FSCC's or AWCC's status by its text (the owner's parser). A file written
// before the status keys existed (issue 12) says only whether the method
// gave a value ("defined", retired by issue 28; docs/output.md): it is read
// as ok, or else as the result's default status, because the measurement
// reads whether a result is ok, never why.
template <class Status, class Parse>
Status status_of(const json& j, Status not_ok, Parse parse, const std::string& row, const std::string& file) {
  if (has(j, key::status)) return parse(text(j, key::status, row, file), awcc::WrittenAt{file, row, key::status});
  if (has(j, key::retired_defined) && j[key::retired_defined].is_boolean()) {
    return j[key::retired_defined].get<bool>() ? Status::ok : not_ok;
  }
  throw awcc::InputError(fmt::format("{}: {}: no '{}'; give a JSON written by pdp process", file, row, key::status));
}

const json& awcc_object(const json& r) {
  static const json none = json::object();
  return has(r, key::awcc) && r[key::awcc].is_object() ? r[key::awcc] : none;
}

// A result of the process JSON is read back into the fields of the
// awcc::ProcessResult that awcc::to_json wrote it from, as far as
// measurement_of reads them: the one builder then makes the measurement of a
// file's row as of a result in memory, status rules included, so that the
// two cannot disagree. First AWCC's outcome (all the status needs).
awcc::ProcessResult awcc_outcome_of(const json& r, const std::string& row, const std::string& file) {
  awcc::ProcessResult p;
  if (has(r, key::awcc) && r[key::awcc].is_object()) {
    const auto& a = r[key::awcc];
    awcc::AwccResult res;
    res.status = status_of(a, res.status, awcc::parse_awcc_status, row + "/awcc", file);
    if (has(a, key::reason) && a[key::reason].is_string()) res.message = a[key::reason].get<std::string>();
    res.probe_corrected = a.value(key::probe_corrected, false);
    // The edge and spread rules' counts (absent from a JSON of an earlier pdp: measured).
    if (has(a, key::turbulence_measured) && a[key::turbulence_measured].is_boolean()) {
      res.turbulence_measured = a[key::turbulence_measured].get<bool>();
    }
    for (auto [k, count] : {std::pair{key::windows_at_least_lag, &res.windows_at_least_lag},
                            std::pair{key::windows_at_greatest_lag, &res.windows_at_greatest_lag},
                            std::pair{key::windows_accepted, &res.windows_accepted}}) {
      if (has(a, k) && a[k].is_number()) *count = whole(a[k].get<double>(), file, fmt::format("awcc.{}", k).c_str());
    }
    if (has(a, key::quality_reason) && a[key::quality_reason].is_string()) {
      res.quality_reason = a[key::quality_reason].get<std::string>();
    }
    p.awcc = std::move(res);
  }
  return p;
}

// AWCC's processing as the JSON's awcc.options records it.
std::optional<Processing> processing_of_json(const json& r, const std::string& row, const std::string& file) {
  const auto& a = awcc_object(r);
  if (!has(a, key::options) || !a[key::options].is_object()) return std::nullopt;
  const auto& o = a[key::options];
  const std::string at = row + "/awcc/options";
  Processing p;
  p.filter_a = required(o, key::filter_a, at, file);
  p.roc = o.value(key::roc, true);
  p.weighting = awcc::parse_weighting(text(o, key::weighting, at, file), {file, at, key::weighting});
  p.signal = awcc::parse_correlation_signal(text(o, key::signal, at, file), {file, at, key::signal});
  p.subsample = awcc::parse_subsample(text(o, key::subsample, at, file), {file, at, key::subsample});
  return p;
}

// One row of either file: AWCC's outcome first; a row AWCC cannot serve needs
// nothing else unless the model's FSCC forest may correct it. `measurement`
// reads the whole row, `processing` how AWCC was processed.
template <class Measure, class Processed>
Correction correct_row(const CorrectionModel& model, const MeasurementResult& outcome, Measure&& measurement,
                       Processed&& processing, const std::string& where, std::vector<std::string>& warnings) {
  if (outcome.status != CorrectionStatus::corrected) {
    if (!model.falls_back_to_fscc(outcome.status)) return not_corrected(outcome.status, outcome.message);
    MeasurementResult result;
    try {
      result = measurement();
    } catch (const std::exception& e) {  // the FSCC forest cannot have the row: AWCC's status stands
      return not_corrected(outcome.status, fmt::format("{}; FSCC forest: {}", outcome.message, e.what()));
    }
    return model.correct(result);
  }
  auto result = measurement();
  const auto processed = processing();
  check_processing(model, processed, where, warnings);
  // The weighting the file records; a file that records no processing is
  // assumed processed as the model's training data (check_processing warns).
  result.measurement.weighting = processed ? processed->weighting : model.processing.weighting;
  return model.correct(result);
}

// A row's notes go to the file's warnings too (the user reads them on
// stderr), named by the row.
void add_notes(const Correction& c, const std::string& where, std::vector<std::string>& warnings) {
  for (const auto& n : c.notes) warnings.push_back(fmt::format("{}: {}", where, n));
  if (!c.turbulence_message.empty()) warnings.push_back(fmt::format("{}: {}", where, c.turbulence_message));
}

// Calls fn(line, cells, "FILE:LINE") for every non-empty row after the
// header; a row with another number of cells than the header is refused.
template <class Fn>
void for_each_row(std::istream& in, const std::string& file, std::size_t columns, Fn&& fn) {
  std::string line;
  for (int number = 2; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = awcc::split_cells(line);
    const std::string where = fmt::format("{}:{}", file, number);
    if (cells.size() != columns) {
      throw awcc::InputError(fmt::format("{}: {} cells where the header has {}", where, cells.size(), columns));
    }
    fn(line, cells, where);
  }
}

constexpr const char* kLayouts =
    "Give a profile CSV of pdp process with AWCC (columns void_fraction, bubble_count_rate, awcc_velocity, "
    "awcc_turbulence_intensity, awcc_windows_accepted, ...; docs/output.md), or the CSV other AWCC tools write "
    "(columns 'u [m/s]', 'u_rms [m/s]', 'c [-]', 'd_32a [m]', optional 'z [m]', with the tip separations and Np "
    "stated)";

// The CSV other AWCC tools write (Kramer's toolbox style): one row per
// position with units in the headers; Tu = u_rms / u, d32 as stated. It
// records neither the accepted windows nor the processing: both are said.
FileCorrection correct_tool_csv(const CorrectionModel& model, const std::string& text, const RowDefaults& d,
                                const std::string& file) {
  FileCorrection out;
  std::stringstream in(text);
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const auto header = awcc::csv_header(line);
  const auto& col = header.index;
  for (const char* name : {"u [m/s]", "u_rms [m/s]", "c [-]", "d_32a [m]"}) {
    if (!col.count(name)) throw awcc::InputError(fmt::format("{}: no column '{}'. {}", file, name, kLayouts));
  }
  out.warnings.push_back(fmt::format("{}: the file records neither AWCC's accepted windows nor its processing: "
                                     "assumed enough windows and the model's processing ({}){}",
                                     file, describe(model.processing),
                                     !model.takes_weighting() ? ""
                                     : d.weighting ? fmt::format(", moments {} as stated", awcc::to_string(*d.weighting))
                                                   : ", the weighting excepted: not known, both answers mixed "
                                                     "(state it: the setting weighting)"));
  out.text = line;
  for (const char* q : {"u", "Tu"}) {
    const char* unit = q[0] == 'u' ? "m/s" : "-";
    out.text += fmt::format(",{}_corrected [{}]", q, unit);
    for (const char* l : correction_level_names) out.text += fmt::format(",{}_q{} [{}]", q, l, unit);
  }
  out.text += ",correction_status [-],correction_forest [-],correction_reason [-],correction_notes [-],"
              "correction_turbulence_reason [-]\n";
  for_each_row(in, file, header.names.size(), [&](const std::string& row, const std::vector<std::string>& cells,
                                            const std::string& where) {
    auto value = [&](const char* name) -> std::optional<double> {
      const std::string& t = cells[col.at(name)];
      if (t.empty() || t == "NaN" || t == "nan") return std::nullopt;
      const auto v = awcc::cell_number(t);
      if (!v) throw awcc::InputError(fmt::format("{}: column '{}' = '{}' is not a number", where, name, t));
      return v;
    };
    Measurement m;
    m.velocity = value("u [m/s]");
    const auto u_rms = value("u_rms [m/s]");
    if (m.velocity && u_rms && *m.velocity != 0.0) m.turbulence_intensity = *u_rms / *m.velocity;
    const auto c_value = value("c [-]");
    m.void_fraction = c_value.value_or(0.0);
    m.d32 = value("d_32a [m]");
    m.dx = need(std::nullopt, d.dx, where, "dx", "streamwise tip separation");
    m.dy = need(std::nullopt, d.dy, where, "dy", "lateral tip separation");
    m.np = static_cast<int>(need(std::nullopt, default_np(d), where, "np", "particles per window"));
    // The record's features, where the tool's CSV has columns of pdp's names.
    auto optional = [&](const char* name) { return col.count(name) ? value(name) : std::nullopt; };
    m.fs = optional("fs").value_or(d.fs.value_or(0.0));
    m.duration = optional("duration").value_or(d.duration.value_or(0.0));
    if (const auto w = optional("awcc_windows_accepted")) m.windows_accepted = whole(*w, where, "awcc_windows_accepted");
    if (const auto w = optional("awcc_windows_total")) m.windows_total = whole(*w, where, "awcc_windows_total");
    m.weighting = d.weighting;  // not known unless stated
    const auto c = c_value ? model.correct(m)
                           : not_corrected(CorrectionStatus::no_bubbles, "no void fraction in the row");
    add_notes(c, where, out.warnings);
    out.text += fmt::format("{}{},{},{},{},{},{}\n", row, quantile_cells(c), to_string(c.status), c.forest,
                            awcc::csv_cell(c.message), awcc::csv_cell(notes_text(c)),
                            awcc::csv_cell(c.turbulence_message));
  });
  return out;
}

}  // namespace

MeasurementResult measurement_of_json(const nlohmann::json& r, const RowDefaults& d, const std::string& file,
                                      const std::string& row) {
  auto p = awcc_outcome_of(r, row, file);
  const bool awcc_usable = measurement_of(p).status == CorrectionStatus::corrected;
  const auto& a = awcc_object(r);
  const std::string at_awcc = row + "/awcc";
  // What every forest shares and FSCC's own.
  if (!has(r, key::tips) || !r[key::tips].is_array() || r[key::tips].empty()) {
    throw awcc::InputError(fmt::format("{}: {}: a result without '{}'; give a JSON written by pdp process", file, row,
                                       key::tips));
  }
  const auto& lead = r[key::tips][0];
  awcc::TipResult tip;
  tip.phase.void_fraction = required(lead, key::void_fraction, row + "/tips/0", file);
  tip.phase.bubble_count_rate = required(lead, key::bubble_count_rate, row + "/tips/0", file);
  p.tips = {tip};
  const auto fs = number(r, key::fs), samples = number(r, key::samples);
  p.info.fs = fs.value_or(d.fs.value_or(0.0));
  if (fs && samples) p.info.frames = whole(*samples, file, "samples");
  if (has(r, key::fscc) && r[key::fscc].is_object()) {
    const auto& f = r[key::fscc];
    awcc::FsccResult res;
    res.status = status_of(f, res.status, awcc::parse_fscc_status, row + "/fscc", file);
    res.velocity = number(f, key::velocity).value_or(0.0);
    res.r12_max = number(f, key::r12_max).value_or(0.0);
    res.turbulence_intensity_chanson = number(f, key::turbulence_intensity_chanson);
    p.fscc = std::move(res);
  }
  if (p.awcc) {
    if (const auto w = number(a, key::windows_accepted)) p.awcc->windows_accepted = whole(*w, file, "awcc.windows_accepted");
    if (const auto w = number(a, key::windows_total)) p.awcc->windows_total = whole(*w, file, "awcc.windows_total");
    p.awcc->np = static_cast<int>(number(a, key::np).value_or(d.np.value_or(0)));
    p.awcc->time_scale_ratio = number(a, key::time_scale_ratio);  // a JSON of an earlier pdp: not known
  }
  p.dx = need(number(r, key::dx), d.dx, file, "dx", "streamwise tip separation");
  p.dy = need(number(r, key::dy), d.dy, file, "dy", "lateral tip separation");
  if (awcc_usable) {
    p.awcc->velocity = required(a, key::velocity, at_awcc, file);
    p.awcc->turbulence_intensity = required(a, key::turbulence_intensity, at_awcc, file);
    p.awcc->windows_accepted = whole(required(a, key::windows_accepted, at_awcc, file), file, "awcc.windows_accepted");
    p.awcc->np =
        static_cast<int>(whole(need(number(a, key::np), default_np(d), file, "np", "particles per window"), file, "np"));
  }
  auto result = measurement_of(p);
  // What the file does not give: the duration it (or the defaults) states
  // where it lacks the samples or the rate, and windows not known.
  auto& m = result.measurement;
  if (!(fs && samples)) m.duration = number(r, key::duration).value_or(d.duration.value_or(0.0));
  if (!number(a, key::windows_accepted)) m.windows_accepted = -1;
  if (!number(a, key::windows_total)) m.windows_total = -1;
  if (!(has(r, key::fscc) && has(r[key::fscc], key::turbulence_intensity_chanson))) m.tu_chanson.reset();
  return result;
}

FileCorrection correct_process_json(const CorrectionModel& model, const std::string& text, const RowDefaults& d,
                                    const std::string& file, const std::string& model_name) {
  FileCorrection out;
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw awcc::InputError(
        fmt::format("{}: not valid JSON ({}); give a pdp process JSON or profile CSV", file, e.what()));
  }
  // A row is named by its JSON pointer: "" for a recording's file, "/profile/3" in a profile.
  auto add = [&](json& r, const std::string& row) {
    const auto outcome = measurement_of(awcc_outcome_of(r, row, file));
    const auto correction = correct_row(
        model, outcome, [&] { return measurement_of_json(r, d, file, row); },
        [&] { return processing_of_json(r, row, file); }, file, out.warnings);
    add_notes(correction, row.empty() ? file : file + ":" + row, out.warnings);
    auto c = to_json(correction);
    c["model"] = model_name;
    r["correction"] = c;
  };
  try {
    if (has(j, key::profile) && j[key::profile].is_array()) {
      auto& rows = j[key::profile];
      for (std::size_t i = 0; i < rows.size(); ++i) add(rows[i], fmt::format("/{}/{}", key::profile, i));
    } else if (has(j, key::tips)) {
      add(j, "");
    } else {
      throw awcc::InputError(fmt::format(
          "{}: neither a recording's result (tips) nor a profile; give a JSON written by pdp process", file));
    }
  } catch (const nlohmann::json::exception& e) {
    // A value of the wrong type (a string where a number or a boolean belongs).
    throw awcc::InputError(fmt::format("{}: not a JSON written by pdp process ({})", file, e.what()));
  }
  out.text = awcc::json_text(j);
  return out;
}

FileCorrection correct_profile_csv(const CorrectionModel& model, const std::string& text, const RowDefaults& d,
                                   const std::string& file) {
  FileCorrection out;
  std::stringstream in(text);
  std::string line;
  if (!std::getline(in, line)) throw awcc::InputError(fmt::format("{}: empty file", file));
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const auto header = awcc::csv_header(line);
  const auto& col = header.index;
  if (!col.count(column::awcc_velocity) && col.count("u [m/s]")) return correct_tool_csv(model, text, d, file);
  for (const auto name : {column::void_fraction, column::bubble_count_rate, column::awcc_velocity,
                          column::awcc_turbulence_intensity, column::awcc_windows_accepted, column::awcc_status}) {
    if (!col.count(name)) {
      throw awcc::InputError(fmt::format("{}: no column '{}': not a layout pdp corrects. {}", file, name, kLayouts));
    }
  }
  if (col.count("correction_in_range")) {
    throw awcc::InputError(fmt::format("{}: already corrected (correction columns present)", file));
  }
  const bool has_processing = col.count(column::awcc_filter_a) && col.count(column::awcc_roc) &&
                              col.count(column::awcc_weighting) && col.count(column::awcc_signal) &&
                              col.count(column::awcc_subsample);
  out.text = line + "," + correction_csv_header() + "\n";
  for_each_row(in, file, header.names.size(), [&](const std::string& row, const std::vector<std::string>& cells,
                                            const std::string& where) {
    auto text_of = [&](std::string_view name) -> std::string {
      const auto it = col.find(name);
      return it == col.end() ? std::string() : cells[it->second];
    };
    auto value = [&](std::string_view name) -> std::optional<double> {
      const std::string t = text_of(name);
      if (t.empty()) return std::nullopt;
      const auto v = awcc::cell_number(t);
      if (!v) throw awcc::InputError(fmt::format("{}: column {} = '{}' is not a number", where, name, t));
      return v;
    };
    const std::string line_label = "line " + where.substr(file.size() + 1);
    auto at = [&](std::string_view name) { return awcc::WrittenAt{file, line_label, name}; };
    // The row read back into the fields of the awcc::ProcessResult that
    // profile_csv_row wrote it from, as far as measurement_of reads them (as
    // the JSON's, measurement_of_json): AWCC's outcome first. An empty
    // status is a recording AWCC was not run on.
    awcc::ProcessResult p;
    if (const auto status = text_of(column::awcc_status); !status.empty()) {
      awcc::AwccResult a;
      a.status = awcc::parse_awcc_status(status, at(column::awcc_status));
      a.message = text_of(column::awcc_reason);
      const auto probe = text_of(column::awcc_probe_corrected);
      a.probe_corrected = !probe.empty() && awcc::parse_switch(probe, at(column::awcc_probe_corrected));
      // The edge and spread rules (empty in a CSV of an earlier pdp or another tool's: measured).
      const auto measured = text_of(column::awcc_turbulence_measured);
      a.turbulence_measured = measured.empty() || awcc::parse_switch(measured, at(column::awcc_turbulence_measured));
      for (auto [name, count] : {std::pair{column::awcc_windows_at_least_lag, &a.windows_at_least_lag},
                                 std::pair{column::awcc_windows_at_greatest_lag, &a.windows_at_greatest_lag},
                                 std::pair{column::awcc_windows_accepted, &a.windows_accepted}}) {
        if (const auto v = value(name)) *count = whole(*v, where, std::string(name).c_str());
      }
      a.quality_reason = text_of(column::awcc_quality_reason);
      p.awcc = std::move(a);
    }
    const auto outcome = measurement_of(p);
    auto measurement = [&] {
      awcc::TipResult tip;
      tip.phase.void_fraction = value(column::void_fraction).value_or(0.0);
      tip.phase.bubble_count_rate = value(column::bubble_count_rate).value_or(0.0);
      p.tips = {tip};
      p.dx = need(value(column::dx), d.dx, where, "dx", "streamwise tip separation");
      p.dy = need(value(column::dy), d.dy, where, "dy", "lateral tip separation");
      if (const auto status = text_of(column::fscc_status); !status.empty()) {
        awcc::FsccResult f;
        f.status = awcc::parse_fscc_status(status, at(column::fscc_status));
        f.velocity = value(column::fscc_velocity).value_or(0.0);
        f.r12_max = value(column::fscc_r12_max).value_or(0.0);
        f.turbulence_intensity_chanson = value(column::fscc_turbulence_intensity_chanson);
        p.fscc = std::move(f);
      }
      const auto accepted = value(column::awcc_windows_accepted), total = value(column::awcc_windows_total);
      if (p.awcc) {
        if (accepted) p.awcc->windows_accepted = whole(*accepted, where, "awcc_windows_accepted");
        if (total) p.awcc->windows_total = whole(*total, where, "awcc_windows_total");
        p.awcc->time_scale_ratio = value(column::awcc_time_scale_ratio);  // a CSV of an earlier pdp: not known
        if (outcome.status == CorrectionStatus::corrected) {
          p.awcc->velocity = *value(column::awcc_velocity);
          p.awcc->turbulence_intensity = *value(column::awcc_turbulence_intensity);
          p.awcc->np = static_cast<int>(
              whole(need(value(column::np), default_np(d), where, "np", "particles per window"), where, "np"));
        }
      }
      auto result = measurement_of(p);
      // What the file does not give: the record's rate and length it (or the
      // defaults) states, and windows not known.
      auto& m = result.measurement;
      m.fs = value(column::fs).value_or(d.fs.value_or(0.0));
      m.duration = value(column::duration).value_or(d.duration.value_or(0.0));
      if (!accepted) m.windows_accepted = -1;
      if (!total) m.windows_total = -1;
      if (!col.count(column::fscc_turbulence_intensity_chanson)) m.tu_chanson.reset();
      return result;
    };
    auto processing = [&]() -> std::optional<Processing> {
      if (!has_processing || !value(column::awcc_filter_a)) return std::nullopt;
      Processing pr;
      pr.filter_a = *value(column::awcc_filter_a);
      pr.roc = awcc::parse_switch(text_of(column::awcc_roc), at(column::awcc_roc));
      pr.weighting = awcc::parse_weighting(text_of(column::awcc_weighting), at(column::awcc_weighting));
      pr.signal = awcc::parse_correlation_signal(text_of(column::awcc_signal), at(column::awcc_signal));
      pr.subsample = awcc::parse_subsample(text_of(column::awcc_subsample), at(column::awcc_subsample));
      return pr;
    };
    const auto c = correct_row(model, outcome, measurement, processing, where, out.warnings);
    add_notes(c, where, out.warnings);
    out.text += row + "," + correction_csv_cells(c) + "\n";
  });
  return out;
}

}  // namespace correction
