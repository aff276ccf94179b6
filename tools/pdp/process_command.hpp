#pragma once
// pdp process: recordings in, phase statistics and FSCC out.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace pdp {

struct ProcessCommandOptions {
  std::vector<std::string> files;
  std::string dx = "0mm", dy = "0mm", fs;            // lengths, frequency (units allowed)
  std::string format = "auto";                       // auto | sndfile | dat | raw | csv
  std::string raw_type = "int16", raw_order = "little";
  int raw_channels = 2;
  long long raw_header = 0;
  std::string volts_per_count;                       // V per count
  std::string csv_header = "auto";                   // auto | yes | no
  std::string time_column = "auto";                  // auto | none | column index
  int leading_channel = 0, trailing_channel = 1;
  std::string method = "both";                       // awcc | fscc | both
  int np = 10;
  double filter_a = 0.4;
  std::string roc = "on";                            // on | off
  std::string weighting = "duration";                // duration | none
  std::string correlate = "binary";                  // binary | raw
  std::string velocity_range;                        // "min,max" velocities
  std::string windows;                               // per-window CSV
  std::string threshold_rule = "histogram";
  std::string threshold;                             // fraction, voltage or "low,high"
  std::string probe = "conductivity";
  std::string bin_width = "0.1V";
  int segments = 1;
  std::string max_lag = "20ms";
  bool felder_lags = false;
  std::string subsample = "none";
  std::string json, csv;                             // output files
  std::string positions, manifest;                   // profile positions
  int histogram_bins = 50;
  std::string correct;                                // correction model (.qrf); empty = no correction
};

CLI::App* setup_process(CLI::App& app, ProcessCommandOptions& options);
int run_process(const ProcessCommandOptions& options);

}  // namespace pdp
