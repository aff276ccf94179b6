#include "process_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>

#include "awcc/atomic_output.hpp"
#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/json_text.hpp"
#include "awcc/options.hpp"
#include "awcc/serialise.hpp"
#include "awcc/units.hpp"
#include "correction/model.hpp"
#include "hints.hpp"
#include "report_command.hpp"
#include "synth/sidecar.hpp"
#include "terminal.hpp"

namespace pdp {

void setup_process(CLI::App& app, Command& command, ProcessCommandOptions& o) {
  auto* cmd = app.add_subcommand("process", "Process recordings: binarisation, phase statistics, FSCC and AWCC");
  command.app = cmd;
  add_config_option(command);
  command.required.push_back(
      cmd->add_option("files", o.files,
                      "recordings (one: a summary; several: a profile, one CSV row each; among several, files that "
                      "are not recordings are skipped with a warning)")
          ->check(CLI::ExistingPath));
  const awcc::ProcessOptions defaults;
  o.library.add(cmd, awcc::process_option_fields(), defaults, "Probe and methods");
  o.library.add(cmd, awcc::reader_option_fields(), defaults.reader, "Input");
  o.library.add(cmd, awcc::binarisation_option_fields(), defaults.binarisation, "Binarisation");
  o.library.add(cmd, awcc::fscc_option_fields(), defaults.fscc_options, "FSCC");
  o.library.add(cmd, awcc::awcc_option_fields(), defaults.awcc_options, "AWCC");
  o.library.add(cmd, awcc::structure_option_fields(), defaults.structure, "Structure (PDFs, clusters, arrivals)");
  cmd->add_option("--preset", o.preset,
                  "felder: Felder's program (his threshold rule, 15 segments of raw voltages, his lags, scale rules, "
                  "bins and defects; FSCC only); options given as well override it")
      ->group("Probe and methods");
  const auto* out = "Output";
  cmd->add_option("--json", o.json, "write the results as JSON (keys in docs/output.md)")->group(out);
  cmd->add_option("--csv", o.csv, "profile CSV file (several recordings; default: stdout)")->group(out);
  cmd->add_option("--windows", o.windows, "AWCC per-window table as CSV (one recording)")->group(out);
  cmd->add_option("--spectrum", o.spectrum,
                  "AWCC's velocity series as CSV: Welch spectrum and autocorrelation (sample-and-hold resampling)")
      ->group(out);
  cmd->add_option("--correlation-functions", o.correlation_functions,
                  "FSCC's auto- and cross-correlation functions as CSV: file, lag_s, r11, r12")
      ->group(out);
  cmd->add_option("--report", o.report,
                  "also write the HTML report of the results (pdp report: figures, table, provenance; needs "
                  "python3-matplotlib and python3-jinja2)")
      ->group(out);
  cmd->add_option("--positions", o.positions, "profile positions, one per file: '2mm,8mm,...'")->group(out);
  cmd->add_option("--manifest", o.manifest, "profile manifest CSV with columns file,position")
      ->check(CLI::ExistingFile)->group(out);
  cmd->add_option("--correct", o.correct,
                  "bias-correct AWCC's velocity and Tu with this model (.qrf from pdp train; samples/model/awcc.qrf "
                  "ships): adds quantiles to the JSON, CSV and report")
      ->check(CLI::ExistingFile)->group("AWCC");
}

namespace {

awcc::ProcessOptions build_options(const ProcessCommandOptions& o) {
  auto settings = o.library.settings();
  if (!o.preset.empty()) settings.push_back({"preset", o.preset, origin_of("preset")});
  const auto p = awcc::process_options(settings);
  if (!o.windows.empty() && o.files.size() != 1) {
    throw std::invalid_argument("--windows writes the window table of one recording; give one file");
  }
  if (!o.windows.empty() && !p.awcc) throw std::invalid_argument("--windows needs --method awcc or both");
  if (!o.spectrum.empty() && (!p.awcc || !p.velocity_spectrum)) {
    throw std::invalid_argument("--spectrum writes AWCC's velocity spectrum: use --method awcc or both, and "
                                "--velocity-spectrum on");
  }
  if (!o.correlation_functions.empty() && !p.fscc) {
    throw std::invalid_argument("--correlation-functions writes FSCC's functions: use --method fscc or both");
  }
  return p;
}

// Positions per file: from --positions, or a manifest CSV "file,position".
std::vector<std::optional<double>> positions_for(const ProcessCommandOptions& o) {
  std::vector<std::optional<double>> out(o.files.size());
  auto length = [](const std::string& text, const std::string& where) {
    try {
      return awcc::parse_quantity(text, awcc::Dimension::length);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("{}: {}", where, e.what()));
    }
  };
  if (!o.positions.empty()) {
    const auto items = awcc::split_cells(o.positions);
    if (items.size() != o.files.size()) {
      throw std::invalid_argument(fmt::format("--positions gives {} positions for {} files; give one per file",
                                              items.size(), o.files.size()));
    }
    for (std::size_t i = 0; i < items.size(); ++i) out[i] = length(items[i], "--positions");
  } else if (!o.manifest.empty()) {
    std::ifstream in(o.manifest);
    std::map<std::string, double> by_name;
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const auto cells = awcc::split_cells(line);
      if (cells.size() < 2) continue;
      try {
        by_name[std::filesystem::path(cells[0]).filename().string()] =
            awcc::parse_quantity(cells[1], awcc::Dimension::length);
      } catch (const std::invalid_argument& e) {
        if (number == 1) continue;  // header row
        throw std::invalid_argument(fmt::format("{}:{}: {}", o.manifest, number, e.what()));
      }
    }
    std::map<std::string, std::string> seen;
    for (std::size_t i = 0; i < o.files.size(); ++i) {
      const auto name = std::filesystem::path(o.files[i]).filename().string();
      if (const auto [at, fresh] = seen.emplace(name, o.files[i]); !fresh) {
        throw std::invalid_argument(fmt::format("{} and {} share the name {}, which the manifest matches by: rename "
                                                "one or give --positions",
                                                at->second, o.files[i], name));
      }
      // A file without a row is refused once it proves to be a recording
      // (a README caught by the same glob is skipped, not positioned).
      if (const auto it = by_name.find(name); it != by_name.end()) out[i] = it->second;
    }
  }
  return out;
}

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

std::string correction_report(const correction::Correction& c) {
  if (!c.corrected()) return fmt::format("  correction: not corrected: {}\n", c.message);
  const auto& u = *c.velocity;
  const auto& t = *c.turbulence_intensity;
  return fmt::format(
      "  correction (quantile regression forest):\n"
      "    velocity             {:.4f} m/s median; 80 % {:.4f} - {:.4f}, 95 % {:.4f} - {:.4f} (measured {:.4f})\n"
      "    turbulence intensity {:.4f} median; 80 % {:.4f} - {:.4f}, 95 % {:.4f} - {:.4f} (measured {:.4f})\n",
      u.median(), u.quantiles[1], u.quantiles[5], u.quantiles[0], u.quantiles[6], u.measured, t.median(),
      t.quantiles[1], t.quantiles[5], t.quantiles[0], t.quantiles[6], t.measured);
}

// Two outputs into one file would leave only the last; inputs are never
// modified, so an output that is one of them is refused.
void check_output_names(const ProcessCommandOptions& o) {
  const std::vector<std::pair<const char*, const std::string*>> named = {
      {"--json", &o.json},       {"--csv", &o.csv},
      {"--windows", &o.windows}, {"--correlation-functions", &o.correlation_functions},
      {"--spectrum", &o.spectrum}, {"--report", &o.report}};
  for (std::size_t a = 0; a < named.size(); ++a) {
    for (std::size_t b = a + 1; b < named.size(); ++b) {
      const auto& x = *named[a].second;
      const auto& y = *named[b].second;
      if (x.empty() || y.empty()) continue;
      std::error_code ec;
      if (x == y || (std::filesystem::exists(x) && std::filesystem::equivalent(x, y, ec))) {
        throw std::invalid_argument(fmt::format("{} and {} both name {}: give each output its own file",
                                                named[a].first, named[b].first, x));
      }
    }
  }
  for (const auto& output : {o.json, o.csv, o.windows, o.correlation_functions, o.spectrum, o.report}) {
    if (output.empty() || !std::filesystem::exists(output)) continue;
    for (const auto& input : o.files) {
      if (std::filesystem::equivalent(output, input)) {
        throw std::invalid_argument(fmt::format("{} is an input recording; choose another output file", output));
      }
    }
  }
}

// Everything decided before the first recording is read.
struct Plan {
  awcc::ProcessOptions options;
  std::vector<std::optional<double>> positions;
  std::optional<correction::CorrectionModel> model;
};

Plan plan_of(const ProcessCommandOptions& o) {
  Plan plan;
  plan.options = build_options(o);
  plan.positions = positions_for(o);
  if (!o.correct.empty() && !plan.options.awcc) {
    throw std::invalid_argument("--correct corrects AWCC's estimates; use --method awcc or both");
  }
  if (!o.correct.empty() && plan.options.awcc_options.probe_correction.enabled) {
    throw std::invalid_argument("--correct and --probe-correction both correct AWCC's velocity: the model was trained "
                                "on synthetic records without bubble-probe interaction; use one of them");
  }
  check_output_names(o);
  // The model is read before any processing: a damaged one, or one trained
  // on other processing, fails fast.
  if (!o.correct.empty()) {
    plan.model = correction::CorrectionModel::load(o.correct);
    if (const auto why = plan.model->mismatch(correction::processing_of(plan.options.awcc_options)); !why.empty()) {
      throw std::invalid_argument(fmt::format("--correct {}: the model was trained on results processed otherwise "
                                              "({}); process with the model's settings or train a model for these",
                                              o.correct, why));
    }
  }
  return plan;
}

// The recordings processed, with the positions and names of those kept.
struct Processed {
  std::vector<awcc::ProcessResult> results;
  std::vector<std::optional<double>> positions;
  std::vector<std::string> inputs, skipped;
};

void warn_about(const std::string& file, const awcc::ProcessResult& r) {
  for (const auto& w : r.info.warnings) spdlog::warn("{}: {}", file, w);
  if (r.fscc) {
    for (const auto& w : r.fscc->warnings) spdlog::warn("{}: {}", file, w);
  }
  if (r.spectrum && !r.spectrum->warning.empty()) spdlog::warn("{}: {}", file, r.spectrum->warning);
}

Processed process_files(const ProcessCommandOptions& o, const Plan& plan) {
  Processed out;
  Progress progress("processing");
  awcc::ProcessWorkspace workspace;  // FFT plans shared by the records
  for (std::size_t i = 0; i < o.files.size(); ++i) {
    // A synthetic recording's sidecar states its volts per count.
    awcc::ProcessOptions file_options = plan.options;
    if (!(file_options.reader.volts_per_count > 0.0)) {
      if (const auto vpc = synth::sidecar_volts_per_count(o.files[i])) file_options.reader.volts_per_count = *vpc;
    }
    try {
      out.results.push_back(awcc::process_recording(o.files[i], file_options, workspace));
    } catch (const awcc::InputError& e) {
      // Among several inputs (a glob), a file that is not a recording is
      // skipped and said; a damaged recording still stops the profile.
      if (o.files.size() == 1 || e.quantity() != "not_a_recording") throw;
      spdlog::warn("skipped: {}", e.what());
      out.skipped.push_back(e.what());
      continue;
    }
    add_flag_hints(out.results.back());
    if (!o.manifest.empty() && !plan.positions[i]) {
      const auto name = std::filesystem::path(o.files[i]).filename().string();
      throw std::invalid_argument(
          fmt::format("{}: no position for {}; add a row '{},<position>'", o.manifest, name, name));
    }
    out.positions.push_back(plan.positions[i]);
    out.inputs.push_back(o.files[i]);
    warn_about(o.files[i], out.results.back());
    spdlog::debug("{}: {:.3f} s", o.files[i], out.results.back().seconds);
    progress(static_cast<double>(i + 1) / static_cast<double>(o.files.size()));
  }
  if (out.results.empty()) {
    throw awcc::InputError(fmt::format("none of the {} inputs is a recording", o.files.size()));
  }
  return out;
}

std::vector<correction::Correction> corrections_of(const Plan& plan, const Processed& p) {
  std::vector<correction::Correction> corrections;
  if (!plan.model) return corrections;
  for (const auto& r : p.results) {
    corrections.push_back(plan.model->correct(correction::measurement_of(r)));
    if (!corrections.back().corrected()) {
      spdlog::warn("{}: not corrected: {}", r.info.path.string(), corrections.back().message);
    }
  }
  return corrections;
}

// Every output rendered (path, text), before any is written, and what goes
// to stdout and to the report when no JSON is written.
struct Rendered {
  std::vector<std::pair<std::string, std::string>> outputs;
  std::string stdout_text, json_for_report;
};

Rendered render(const ProcessCommandOptions& o, const Plan& plan, const Processed& p,
                const std::vector<correction::Correction>& corrections) {
  const auto& results = p.results;
  const auto& positions = p.positions;
  const bool corrected = plan.model.has_value();
  auto correction_json = [&](std::size_t i) {
    auto c = correction::to_json(corrections[i]);
    c["model"] = std::filesystem::path(o.correct).filename().string();
    return c;
  };
  Rendered out;
  if (!o.json.empty() || !o.report.empty()) {
    nlohmann::json j;
    if (results.size() == 1 && o.files.size() == 1) {
      j = awcc::to_json(results[0]);
      if (corrected) j["correction"] = correction_json(0);
    } else {
      j["profile"] = nlohmann::json::array();
      for (std::size_t i = 0; i < results.size(); ++i) {
        auto row = awcc::to_json(results[i]);
        row["position"] = positions[i] ? nlohmann::json(*positions[i]) : nlohmann::json(nullptr);
        if (corrected) row["correction"] = correction_json(i);
        j["profile"].push_back(row);
      }
      if (!p.skipped.empty()) j["skipped"] = p.skipped;
    }
    // Hashing the inputs costs a read of each: only for the JSON, which records it.
    j["provenance"] = awcc::provenance_json(plan.options, p.inputs, command_line());
    if (!o.json.empty()) out.outputs.emplace_back(o.json, awcc::json_text(j));
    else out.json_for_report = awcc::json_text(j);
  }
  if (!o.windows.empty() && results[0].awcc) out.outputs.emplace_back(o.windows, awcc::awcc_windows_csv(*results[0].awcc));
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
    if (o.csv.empty()) out.stdout_text = table;
    else out.outputs.emplace_back(o.csv, table);
  }
  return out;
}

}  // namespace

int run_process(ProcessCommandOptions& o) {
  Plan plan;
  try {
    plan = plan_of(o);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  Processed processed;
  try {
    processed = process_files(o, plan);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  const auto corrections = corrections_of(plan, processed);
  try {
    // A run fails whole or writes all: every folder is checked before any output is written.
    const auto rendered = render(o, plan, processed, corrections);
    for (const auto& [path, text] : rendered.outputs) awcc::check_output_folder(path);
    if (!o.report.empty()) awcc::check_output_folder(o.report);
    for (const auto& [path, text] : rendered.outputs) awcc::write_text_atomically(path, text);
    fmt::print("{}", rendered.stdout_text);
    std::fflush(stdout);
    if (!o.report.empty()) return report_of(o, rendered.json_for_report);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
