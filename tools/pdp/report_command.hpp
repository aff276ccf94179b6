#pragma once
// pdp report: one self-contained HTML page (figures, table, provenance) for
// a pdp process JSON. The page is drawn by the Python module's pdp.report
// (matplotlib and Jinja2); this command finds Python and the module, runs
// it and passes its exit status on (docs/guide/settings.md, "Exit status"; 5 when Python or
// a package is missing, with what to install). The report's options are
// declared once, by pdp.report; this command hands them over unchanged.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "command.hpp"

namespace pdp {

struct ReportOptions {
  std::vector<std::string> arguments;  ///< handed to pdp.report unchanged: it declares the report's options
};

void setup_report(CLI::App& app, Command& command, ReportOptions& options);
int run_report(const ReportOptions& options);

/// Runs the Python module's page script (pdp/report.py: `arguments` are
/// PROFILE.json -o REPORT.html ...; pdp/design_report.py for pdp design).
/// Returns an exit code of docs/guide/settings.md's table (logs the reason). Shared by
/// pdp report, pdp process --report and pdp design --report.
int write_report(std::vector<std::string> arguments, const std::string& script = "report.py");

}  // namespace pdp
