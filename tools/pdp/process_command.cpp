#include "process_command.hpp"

#include <fmt/format.h>

#include <cstdio>

#include "awcc/atomic_output.hpp"
#include "awcc/options.hpp"
#include "process_steps.hpp"
#include "study/profile_run.hpp"

namespace pdp {


void setup_process(CLI::App& app, Command& command, ProcessCommandOptions& o) {
  auto* cmd = app.add_subcommand("process", "Process recordings: binarisation, phase statistics, FSCC and AWCC");
  command.app = cmd;
  add_config_option(command);
  // Not required: a manifest's rows may name the recordings (run_process).
  path_option(cmd->add_option("files", o.files,
                              "recordings (one: a summary; several: a profile, one CSV row each; among several, files "
                              "that are not recordings are skipped with a warning); with --manifest alone, its rows'"))
      ->check(CLI::ExistingPath);
  const awcc::ProcessOptions defaults;
  o.library.add(cmd, awcc::process_option_fields(), defaults, "Probe and methods");
  auto& probe = command.option_tables.emplace_back("probe", std::vector<std::string>{});
  for (const auto& f : awcc::probe_option_fields()) probe.second.emplace_back(f.name);
  o.library.add(cmd, awcc::reader_option_fields(), defaults.reader, "Input");
  o.library.add(cmd, awcc::binarisation_option_fields(), defaults.binarisation, "Binarisation");
  o.library.add(cmd, awcc::fscc_option_fields(), defaults.fscc_options, "FSCC");
  o.library.add(cmd, awcc::awcc_option_fields(), defaults.awcc_options, "AWCC");
  o.library.add(cmd, awcc::structure_option_fields(), defaults.structure, "Structure (PDFs, clusters, arrivals)");
  o.library.add(cmd, awcc::event_option_fields(), defaults.event_options, "Event detection (method events)");
  o.library.add(cmd, awcc::multi_tip_option_fields(), defaults.multi_tip_options, "Multi-tip probes");
  o.flow.add(cmd, awcc::profile_flow_option_fields(), awcc::ProfileFlowOptions{},
             "Profile quantities (several recordings with positions: Y90, C_mean, discharge, models)");
  cmd->add_option("--preset", o.preset,
                  "felder: Felder's program (his threshold rule, 15 segments of raw voltages, his lags, scale rules, "
                  "bins and defects; FSCC only, whole-sample peak); kramer: Kramer's AWCC toolbox (thres.m, raw "
                  "voltages correlated, whole-sample peak); options given as well override it")
      ->group("Probe and methods");
  const auto* out = "Output";
  path_option(cmd->add_option("--json", o.json, "write the results as JSON (keys in docs/output.md)"))->group(out);
  path_option(cmd->add_option("--csv", o.csv, "profile CSV file (several recordings; default: stdout)"))->group(out);
  add_mat_options(cmd, o.mat, "the AWCC windows and bubbles (one recording) or profile_table (a profile)", out);
  path_option(cmd->add_option("--windows", o.windows, "AWCC per-window table as CSV (one recording)"))->group(out);
  path_option(cmd->add_option("--bubbles", o.bubbles,
                              "per-bubble table as CSV (one recording): the multi-tip vectors, or event detection's "
                              "pairs (method events); with both, event detection's goes to FILE.events.csv"))
      ->group(out);
  path_option(
      cmd->add_option("--spectrum", o.spectrum,
                      "AWCC's velocity series as CSV: Welch spectrum and autocorrelation (sample-and-hold resampling)"))
      ->group(out);
  path_option(cmd->add_option("--correlation-functions", o.correlation_functions,
                              "FSCC's auto- and cross-correlation functions as CSV: file, lag_s, r11, r12"))
      ->group(out);
  path_option(
      cmd->add_option("--report", o.report,
                      "also write the HTML report of the results (pdp report: figures, table, provenance; needs "
                      "python3-matplotlib and python3-jinja2)"))
      ->group(out);
  cmd->add_option("--positions", o.positions, "profile positions, one per file: '2mm,8mm,...'")->group(out);
  path_option(cmd->add_option("--manifest", o.manifest, "profile manifest CSV with columns file,position"))
      ->check(CLI::ExistingFile)
      ->group(out);
  path_option(cmd->add_option(
                  "--correct", o.correct,
                  "bias-correct AWCC's velocity and Tu with this model (.qrf from pdp train; samples/model/awcc.qrf "
                  "ships): adds quantiles to the JSON, CSV and report"))
      ->check(CLI::ExistingFile)
      ->group("AWCC");
}


int run_process(ProcessCommandOptions& o) {
  Plan plan;
  try {
    if (o.files.empty() && o.manifest.empty()) {
      throw std::invalid_argument("files is required: give the recordings, or --manifest FILE whose rows name them "
                                  "with their positions; see pdp process --help");
    }
    if (o.files.empty()) o.files = study::files_of_manifest(o.manifest);
    plan = plan_of(o);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  study::ProfileRun processed;
  try {
    processed = process_files(o, plan);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  try {
    // A run fails whole or writes all: every folder is checked before any output is written.
    const auto rendered = render(o, plan, processed);
    for (const auto& [path, text] : rendered.outputs) awcc::check_output_folder(path);
    if (!o.report.empty()) awcc::check_output_folder(o.report);
    if (rendered.mat) awcc::check_output_folder(rendered.mat->path);
    for (const auto& [path, text] : rendered.outputs) awcc::write_text_atomically(path, text);
    if (const auto& m = rendered.mat) awcc::write_mat(m->path, m->document, m->tables, m->version);
    fmt::print("{}", rendered.stdout_text);
    std::fflush(stdout);
    if (!o.report.empty()) return report_of(o, rendered.json_for_report);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
