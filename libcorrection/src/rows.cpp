#include "correction/rows.hpp"

#include <fmt/format.h>

#include <cmath>

#include <map>
#include <sstream>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/json_text.hpp"

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

Processing parse_processing(double filter_a, const std::string& roc, const std::string& weighting,
                            const std::string& signal, const std::string& subsample) {
  Processing p;
  p.filter_a = filter_a;
  p.roc = roc == "on" || roc == "true";
  p.weighting = weighting == "none" ? awcc::Weighting::none : awcc::Weighting::duration;
  p.signal = signal == "raw" ? awcc::CorrelationSignal::raw : awcc::CorrelationSignal::binary;
  p.subsample = subsample == "parabolic" ? awcc::Subsample::parabolic : awcc::Subsample::none;
  return p;
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

// A status of the process JSON (FSCC's or AWCC's) by its text. A file written
// before the key existed says only whether the method gave a value
// ("defined"); not ok is then the result's default status: the measurement
// reads whether a result is ok, never why.
template <class Status>
Status status_of(const json& j, Status not_ok, const std::string& file, const char* where) {
  if (j.contains("status") && j["status"].is_string()) {
    const auto text = j["status"].get<std::string>();
    for (int k = 0; k < 64; ++k) {
      const auto status = static_cast<Status>(k);
      const auto name = awcc::to_string(status);
      if (name == "?") break;
      if (name == text) return status;
    }
    throw awcc::InputError(fmt::format("{}: {}.status = '{}' is not a status pdp writes; give a JSON written by pdp "
                                       "process",
                                       file, where, text));
  }
  return j.value("defined", false) ? Status::ok : not_ok;
}

std::optional<double> number(const json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || !j[key].is_number()) return std::nullopt;
  return j[key].get<double>();
}

double required(const json& j, const char* key, const char* where, const std::string& file) {
  const auto v = number(j, key);
  if (!v) throw awcc::InputError(fmt::format("{}: no number '{}' in {}; give a JSON written by pdp process", file, key, where));
  return *v;
}

const json& awcc_object(const json& r) {
  static const json none = json::object();
  return r.contains("awcc") && r["awcc"].is_object() ? r["awcc"] : none;
}

// A result of the process JSON is read back into the fields of the
// awcc::ProcessResult that awcc::to_json wrote it from, as far as
// measurement_of reads them: the one builder then makes the measurement of a
// file's row as of a result in memory, status rules included, so that the
// two cannot disagree. First AWCC's outcome (all the status needs).
awcc::ProcessResult awcc_outcome_of(const json& r, const std::string& file) {
  awcc::ProcessResult p;
  if (r.contains("awcc") && r["awcc"].is_object()) {
    const auto& a = r["awcc"];
    awcc::AwccResult res;
    res.status = status_of(a, res.status, file, "awcc");
    if (a.contains("reason") && a["reason"].is_string()) res.message = a["reason"].get<std::string>();
    res.probe_corrected = a.value("probe_corrected", false);
    p.awcc = std::move(res);
  }
  return p;
}

Correction correct_json_row(const CorrectionModel& model, const json& r, const RowDefaults& d, const std::string& file,
                            std::vector<std::string>& warnings) {
  // AWCC's status first: a row AWCC cannot serve needs nothing else unless
  // the model's FSCC forest may correct it.
  const auto outcome = measurement_of(awcc_outcome_of(r, file));
  if (outcome.status != CorrectionStatus::corrected) {
    if (!model.falls_back_to_fscc(outcome.status)) return not_corrected(outcome.status, outcome.message);
    MeasurementResult result;
    try {
      result = measurement_of_json(r, d, file);
    } catch (const std::exception& e) {  // the FSCC forest cannot have the row: AWCC's status stands
      return not_corrected(outcome.status, fmt::format("{}; FSCC forest: {}", outcome.message, e.what()));
    }
    return model.correct(result);
  }
  const auto result = measurement_of_json(r, d, file);
  const auto& a = awcc_object(r);
  std::optional<Processing> processing;
  if (a.contains("options") && a["options"].is_object()) {
    const auto& o = a["options"];
    processing = parse_processing(required(o, "filter_a", "awcc.options", file), o.value("roc", true) ? "on" : "off",
                                  o.value("weighting", ""), o.value("signal", ""), o.value("subsample", ""));
  }
  check_processing(model, processing, file, warnings);
  return model.correct(result);
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
  const auto header = awcc::split_cells(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  for (const char* name : {"u [m/s]", "u_rms [m/s]", "c [-]", "d_32a [m]"}) {
    if (!col.count(name)) throw awcc::InputError(fmt::format("{}: no column '{}'. {}", file, name, kLayouts));
  }
  out.warnings.push_back(fmt::format("{}: the file records neither AWCC's accepted windows nor its processing: "
                                     "assumed enough windows and the model's processing ({})",
                                     file, describe(model.processing)));
  out.text = line;
  for (const char* q : {"u", "Tu"}) {
    const char* unit = q[0] == 'u' ? "m/s" : "-";
    out.text += fmt::format(",{}_corrected [{}]", q, unit);
    for (const char* l : correction_level_names) out.text += fmt::format(",{}_q{} [{}]", q, l, unit);
  }
  out.text += ",correction_status [-],correction_reason [-]\n";
  for_each_row(in, file, header.size(), [&](const std::string& row, const std::vector<std::string>& cells,
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
    const auto c = c_value ? model.correct(m)
                           : not_corrected(CorrectionStatus::no_bubbles, "no void fraction in the row");
    out.text += row;
    for (const auto* q : {&c.velocity, &c.turbulence_intensity}) {
      if (*q) {
        out.text += fmt::format(",{:.10g}", (*q)->median());
        for (double v : (*q)->quantiles) out.text += fmt::format(",{:.10g}", v);
      } else {
        out.text += std::string(1 + correction_levels.size(), ',');
      }
    }
    out.text += fmt::format(",{},{}\n", to_string(c.status), awcc::csv_cell(c.message));
  });
  return out;
}

}  // namespace

MeasurementResult measurement_of_json(const nlohmann::json& r, const RowDefaults& d, const std::string& file) {
  auto p = awcc_outcome_of(r, file);
  const bool awcc_usable = measurement_of(p).status == CorrectionStatus::corrected;
  const auto& a = awcc_object(r);
  // What every forest shares and FSCC's own.
  if (!r.contains("tips") || !r["tips"].is_array() || r["tips"].empty()) {
    throw awcc::InputError(fmt::format("{}: a result without 'tips'; give a JSON written by pdp process", file));
  }
  const auto& lead = r["tips"][0];
  awcc::TipResult tip;
  tip.phase.void_fraction = required(lead, "void_fraction", "tips[0]", file);
  tip.phase.bubble_count_rate = required(lead, "bubble_count_rate", "tips[0]", file);
  p.tips = {tip};
  const auto fs = number(r, "fs"), samples = number(r, "samples");
  p.info.fs = fs.value_or(d.fs.value_or(0.0));
  if (fs && samples) p.info.frames = whole(*samples, file, "samples");
  if (r.contains("fscc") && r["fscc"].is_object()) {
    const auto& f = r["fscc"];
    awcc::FsccResult res;
    res.status = status_of(f, res.status, file, "fscc");
    res.velocity = number(f, "velocity").value_or(0.0);
    res.r12_max = number(f, "r12_max").value_or(0.0);
    p.fscc = std::move(res);
  }
  if (p.awcc) {
    if (const auto w = number(a, "windows_accepted")) p.awcc->windows_accepted = whole(*w, file, "awcc.windows_accepted");
    if (const auto w = number(a, "windows_total")) p.awcc->windows_total = whole(*w, file, "awcc.windows_total");
    p.awcc->np = static_cast<int>(number(a, "np").value_or(d.np.value_or(0)));
  }
  p.dx = need(number(r, "dx"), d.dx, file, "dx", "streamwise tip separation");
  p.dy = need(number(r, "dy"), d.dy, file, "dy", "lateral tip separation");
  if (awcc_usable) {
    p.awcc->velocity = required(a, "velocity", "awcc", file);
    p.awcc->turbulence_intensity = required(a, "turbulence_intensity", "awcc", file);
    p.awcc->windows_accepted = whole(required(a, "windows_accepted", "awcc", file), file, "awcc.windows_accepted");
    p.awcc->np = static_cast<int>(whole(need(number(a, "np"), default_np(d), file, "np", "particles per window"), file, "np"));
  }
  auto result = measurement_of(p);
  // What the file does not give: the duration it (or the defaults) states
  // where it lacks the samples or the rate, and windows not known.
  auto& m = result.measurement;
  if (!(fs && samples)) m.duration = number(r, "duration").value_or(d.duration.value_or(0.0));
  if (!number(a, "windows_accepted")) m.windows_accepted = -1;
  if (!number(a, "windows_total")) m.windows_total = -1;
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
  auto add = [&](json& row) {
    auto c = to_json(correct_json_row(model, row, d, file, out.warnings));
    c["model"] = model_name;
    row["correction"] = c;
  };
  try {
    if (j.is_object() && j.contains("profile") && j["profile"].is_array()) {
      for (auto& row : j["profile"]) add(row);
    } else if (j.is_object() && j.contains("tips")) {
      add(j);
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
  const auto header = awcc::split_cells(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  if (!col.count("awcc_velocity") && col.count("u [m/s]")) return correct_tool_csv(model, text, d, file);
  for (const char* name :
       {"void_fraction", "bubble_count_rate", "awcc_velocity", "awcc_turbulence_intensity", "awcc_windows_accepted"}) {
    if (!col.count(name)) {
      throw awcc::InputError(fmt::format("{}: no column '{}': not a layout pdp corrects. {}", file, name, kLayouts));
    }
  }
  if (col.count("correction_in_range")) {
    throw awcc::InputError(fmt::format("{}: already corrected (correction columns present)", file));
  }
  const bool has_processing = col.count("awcc_filter_a") && col.count("awcc_roc") && col.count("awcc_weighting") &&
                              col.count("awcc_signal") && col.count("awcc_subsample");
  out.text = line + "," + correction_csv_header() + "\n";
  for_each_row(in, file, header.size(), [&](const std::string& row, const std::vector<std::string>& cells,
                                            const std::string& where) {
    auto text_of = [&](const char* name) -> std::string {
      const auto it = col.find(name);
      return it == col.end() ? std::string() : cells[it->second];
    };
    auto value = [&](const char* name) -> std::optional<double> {
      const std::string t = text_of(name);
      if (t.empty()) return std::nullopt;
      const auto v = awcc::cell_number(t);
      if (!v) throw awcc::InputError(fmt::format("{}: column {} = '{}' is not a number", where, name, t));
      return v;
    };
    MeasurementResult result;
    Measurement& m = result.measurement;
    const auto u = value("awcc_velocity"), tu = value("awcc_turbulence_intensity");
    const std::string probe = text_of("awcc_probe_corrected");
    if (!u || !tu) {
      result.status = CorrectionStatus::no_awcc_velocity;
      result.message = "AWCC gave no velocity";
    } else if (probe == "1" || probe == "true") {
      result.status = CorrectionStatus::probe_corrected;
      result.message = "AWCC's velocity is bubble-probe corrected (probe-correction on): the model corrects the "
                       "uncorrected AWCC; process without the probe correction to correct it";
    }
    const bool awcc_usable = result.status == CorrectionStatus::corrected;
    // What every forest shares and FSCC's own.
    auto gather = [&] {
      m.void_fraction = value("void_fraction").value_or(0.0);
      m.bubble_count_rate = value("bubble_count_rate").value_or(0.0);
      m.dx = need(value("dx"), d.dx, where, "dx", "streamwise tip separation");
      m.dy = need(value("dy"), d.dy, where, "dy", "lateral tip separation");
      if (const auto w = value("awcc_windows_accepted")) m.windows_accepted = whole(*w, where, "awcc_windows_accepted");
      if (const auto w = value("awcc_windows_total")) m.windows_total = whole(*w, where, "awcc_windows_total");
      m.fs = value("fs").value_or(d.fs.value_or(0.0));
      m.duration = value("duration").value_or(d.duration.value_or(0.0));
      m.fscc_velocity = value("fscc_velocity");
      m.r12_max = value("fscc_r12_max");
    };
    Correction c;
    if (!awcc_usable && !model.falls_back_to_fscc(result.status)) {
      c = not_corrected(result.status, result.message);
    } else if (!awcc_usable) {
      try {
        gather();
        c = model.correct(result);
      } catch (const std::exception& e) {  // the FSCC forest cannot have the row: AWCC's status stands
        c = not_corrected(result.status, fmt::format("{}; FSCC forest: {}", result.message, e.what()));
      }
    } else {
      std::optional<Processing> processing;
      if (has_processing && value("awcc_filter_a")) {
        processing = parse_processing(*value("awcc_filter_a"), text_of("awcc_roc"), text_of("awcc_weighting"),
                                      text_of("awcc_signal"), text_of("awcc_subsample"));
      }
      check_processing(model, processing, where, out.warnings);
      m.velocity = u;
      m.turbulence_intensity = tu;
      gather();
      m.np = static_cast<int>(whole(need(value("np"), default_np(d), where, "np", "particles per window"), where, "np"));
      c = model.correct(result);
    }
    out.text += row + "," + correction_csv_cells(c) + "\n";
  });
  return out;
}

}  // namespace correction
