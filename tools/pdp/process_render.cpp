#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "awcc/atomic_output.hpp"
#include "awcc/errors.hpp"
#include "awcc/json_text.hpp"
#include "awcc/read_back.hpp"
#include "awcc/serialise.hpp"
#include "correction/profile_rows.hpp"
#include "command.hpp"
#include "process_steps.hpp"
#include "report_command.hpp"

namespace pdp {

namespace {

// The correction of one recording: the corrected values, or why there are
// none, and the notes. A row the FSCC forest corrected has no corrected Tu,
// and says so (a number there would read as one).
std::string correction_report(const correction::Correction& c) {
  std::string out;
  if (!c.corrected()) {
    out = fmt::format("  correction: not corrected: {}\n", c.why_not());
    if (c.large_bubbles) out += fmt::format("    turbulence intensity: {}\n", c.turbulence_message);
  } else {
    const auto& u = *c.velocity;
    out = fmt::format(
        "  correction (quantile regression forest, {} forest):\n"
        "    velocity             {:.4f} m/s median; 80 % {:.4f} - {:.4f}, 95 % {:.4f} - {:.4f} (measured {:.4f})\n",
        c.forest == "fscc" ? "FSCC" : "AWCC", u.median(), u.lower(correction::interval80),
        u.upper(correction::interval80), u.lower(correction::interval95), u.upper(correction::interval95), u.measured);
    if (const auto& t = c.turbulence_intensity; t && c.large_bubbles) {
      out += fmt::format("    turbulence intensity: {} (forest's median {:.4f}, measured {:.4f})\n", c.turbulence_message,
                         t->median(), t->measured);
    } else if (t) {
      out += fmt::format(
          "    turbulence intensity {:.4f} median; 80 % {:.4f} - {:.4f}, 95 % {:.4f} - {:.4f} (measured {:.4f})\n",
          t->median(), t->lower(correction::interval80), t->upper(correction::interval80),
          t->lower(correction::interval95), t->upper(correction::interval95), t->measured);
    } else {
      out += "    turbulence intensity not corrected (the FSCC forest corrects the velocity only)\n";
    }
  }
  for (const auto& n : c.notes) out += fmt::format("    note: {}\n", n);
  return out;
}

// A column of a per-window or per-bubble table as a MAT column: numbers, or
// text for the one text column.
template <typename Column, typename Row>
awcc::MatTable::Column mat_column(const Column& c, const std::vector<Row>& rows) {
  awcc::MatTable::Column out{std::string(c.name), std::string(c.unit), {}};
  if (c.text) {
    std::vector<std::string> v;
    for (const auto& r : rows) v.emplace_back(c.text(r));
    out.values = std::move(v);
  } else {
    std::vector<double> v;
    for (const auto& r : rows) v.push_back(c.value(r));
    out.values = std::move(v);
  }
  return out;
}

template <typename Columns, typename Row>
awcc::MatTable mat_table(std::string name, const Columns& columns, const std::vector<Row>& rows) {
  awcc::MatTable t{std::move(name), {}};
  for (const auto& c : columns) t.columns.push_back(mat_column(c, rows));
  return t;
}

// The tables of --mat (awcc/mat_output.hpp): one recording's AWCC windows
// and bubbles; a profile's rows.
std::vector<awcc::MatTable> mat_tables(const std::vector<awcc::ProcessResult>& results, const nlohmann::json& j) {
  std::vector<awcc::MatTable> out;
  if (results.size() == 1) {
    const auto& r = results[0];
    if (r.awcc) out.push_back(mat_table("windows", awcc::awcc_window_columns(), r.awcc->windows));
    if (r.events) out.push_back(mat_table("event_bubbles", awcc::event_bubble_columns(), r.events->bubbles));
    if (r.probe) out.push_back(mat_table("bubbles", awcc::multi_tip_bubble_columns(), r.probe->vectors.bubbles));
  }
  for (auto& t : profile_mat_tables(j)) out.push_back(std::move(t));
  return out;
}

}  // namespace

// The report is drawn from the JSON: the --json file, or the same text in a
// hidden scratch file beside the report, removed afterwards.
int report_of(const ProcessCommandOptions& o, const std::string& json_text) {
  if (!o.json.empty()) return write_report({o.json, "-o", o.report});
  const auto folder = std::filesystem::absolute(o.report).parent_path();
  std::string scratch = (folder / ".pdp-report-XXXXXX.json").string();
  const int fd = mkstemps(scratch.data(), 5);
  if (fd < 0) throw awcc::OutputError(fmt::format("{}: cannot create a scratch file for the report's JSON: {}",
                                                  folder.string(), std::strerror(errno)));
  ::close(fd);
  struct Remove {
    std::string path;
    ~Remove() { std::error_code ec; std::filesystem::remove(path, ec); }
  } remove{scratch};
  awcc::write_text_atomically(scratch, json_text);
  return write_report({scratch, "-o", o.report, "--input-name", "the results of pdp process (no --json written)"});
}

Rendered render(const ProcessCommandOptions& o, const Plan& plan, const study::ProfileRun& p) {
  const auto& results = p.results;
  const auto& positions = p.positions;
  const auto& corrections = p.corrections;
  const bool corrected = plan.model.has_value();
  const auto& flow = p.flow;
  Rendered out;
  if (!o.json.empty() || !o.report.empty() || !o.mat.path.empty()) {
    auto j = study::profile_run_json(p, std::filesystem::path(o.correct).filename().string());
    // The inputs' digests were taken as they were read (process_files asks for them when the JSON is written).
    std::vector<awcc::ProvenanceInput> inputs;
    for (std::size_t i = 0; i < p.inputs.size(); ++i) inputs.push_back({p.inputs[i], results[i].input_sha256});
    j["provenance"] = awcc::provenance_json(plan.options, inputs, command_line());
    if (!o.mat.path.empty()) out.mat = Rendered::Mat{o.mat.path, j, mat_tables(results, j), o.mat.version()};
    if (!o.json.empty()) out.outputs.emplace_back(o.json, awcc::json_text(j));
    else if (!o.report.empty()) out.json_for_report = awcc::json_text(j);
  }
  if (!o.windows.empty() && results[0].awcc) out.outputs.emplace_back(o.windows, awcc::awcc_windows_csv(*results[0].awcc));
  if (!o.bubbles.empty()) {
    const auto& r = results[0];
    if (!r.probe && !r.events) {
      throw std::invalid_argument(fmt::format("--bubbles: {} was processed as a tip pair (it has fewer than four tips "
                                              "declared or stated) without event detection: use --method events",
                                              r.info.path.string()));
    }
    if (r.probe) out.outputs.emplace_back(o.bubbles, awcc::multi_tip_bubbles_csv(r.probe->vectors));
    if (r.events) {
      const std::filesystem::path base(o.bubbles);
      const std::string file =
          r.probe ? (base.parent_path() / (base.stem().string() + ".events" + base.extension().string())).string()
                  : o.bubbles;
      out.outputs.emplace_back(file, awcc::event_bubbles_csv(*r.events));
    }
  }
  std::vector<const awcc::ProcessResult*> all;
  for (const auto& r : results) all.push_back(&r);
  if (!o.correlation_functions.empty()) {
    out.outputs.emplace_back(o.correlation_functions, awcc::correlation_functions_csv(all));
  }
  if (!o.spectrum.empty()) out.outputs.emplace_back(o.spectrum, awcc::velocity_spectrum_csv(all));
  // The structure tables sit next to the profile CSV: profile.csv, profile_chord_pdf.csv, ...
  if (!o.csv.empty() && plan.options.structure.enabled) {
    const std::filesystem::path base(o.csv);
    for (const auto& [suffix, text] : awcc::structure_csv_tables(all, positions)) {
      out.outputs.emplace_back((base.parent_path() / (base.stem().string() + suffix)).string(), text);
    }
  }
  if (results.size() == 1 && o.files.size() == 1 && o.csv.empty()) {
    out.stdout_text = results[0].report();
    if (corrected) out.stdout_text += correction_report(corrections[0]);
  } else {
    std::string table = awcc::profile_csv_header();
    table += corrected ? "," + correction::correction_csv_header() + "\n" : "\n";
    for (std::size_t i = 0; i < results.size(); ++i) {
      table += awcc::profile_csv_row(results[i], positions[i]);
      table += corrected ? "," + correction::correction_csv_cells(corrections[i]) + "\n" : "\n";
    }
    if (o.csv.empty()) {
      out.stdout_text = table;
    } else {
      out.outputs.emplace_back(o.csv, table);
      // stdout holds no table: the profile's flow quantities are read there.
      if (flow) out.stdout_text = flow->report();
    }
  }
  return out;
}

}  // namespace pdp
