#pragma once
// pdp process: recordings in, phase statistics, FSCC and AWCC out (a summary,
// JSON, a profile CSV, the window table), optionally bias-corrected.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli_options.hpp"
#include "mat_cli.hpp"
#include "command.hpp"

namespace pdp {

struct ProcessCommandOptions {
  std::vector<std::string> files;
  OptionSet library;                                 // the libraries' options (awcc/options.hpp)
  OptionSet flow;                                    // a profile's flow quantities (awcc/profile_flow.hpp)
  std::string json, csv, windows, bubbles, correlation_functions, spectrum, report;  // output files
  MatOption mat;                                     // --mat, --mat-v73
  std::string preset;                                // named option values (awcc::preset_settings)
  std::string positions, manifest;                   // profile positions
  std::string correct;                               // correction model (.qrf); empty = no correction
};

void setup_process(CLI::App& app, Command& command, ProcessCommandOptions& options);
int run_process(ProcessCommandOptions& options);

}  // namespace pdp
