#pragma once
// pdp report: one self-contained HTML page (figures, table, provenance) for
// a pdp process JSON. The page is drawn by the Python module's pdp.report
// (matplotlib and Jinja2); this command finds Python and the module, runs
// it and passes its exit status on (README, "Exit status"; 5 when Python or
// a package is missing, with what to install).

#include <CLI/CLI.hpp>
#include <string>

#include "command.hpp"

namespace pdp {

struct ReportOptions {
  std::string input;       ///< pdp process JSON (a profile or one recording)
  std::string output;      ///< the HTML page
  bool no_detail = false;  ///< leave out the per-position figures (no recording is read again)
};

void setup_report(CLI::App& app, Command& command, ReportOptions& options);
int run_report(const ReportOptions& options);

/// Runs pdp.report on `json` to write `html`; `detail` draws the per-position
/// figures. Returns an exit code of the README's table (logs the reason).
/// Shared by pdp report and pdp process --report.
int write_report(const std::string& json, const std::string& html, bool detail);

}  // namespace pdp
