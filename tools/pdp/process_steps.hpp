#pragma once
// The steps of pdp process (process_command.cpp runs them in turn): the plan
// made before any recording is read (process_plan.cpp), the recordings
// processed and corrected (process_files.cpp), every output rendered before
// any is written (process_render.cpp).

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "awcc/process.hpp"
#include "awcc/profile_flow.hpp"
#include "correction/model.hpp"
#include "process_command.hpp"

namespace pdp {

// Everything decided before the first recording is read.
struct Plan {
  awcc::ProcessOptions options;
  std::vector<std::optional<double>> positions;
  std::optional<correction::CorrectionModel> model;
  awcc::ProfileFlowOptions flow;  ///< a profile's flow quantities
};

Plan plan_of(const ProcessCommandOptions& o);

// The recordings processed, with the positions and names of those kept.
struct Processed {
  std::vector<awcc::ProcessResult> results;
  std::vector<std::optional<double>> positions;
  std::vector<std::string> inputs, skipped;
};

Processed process_files(const ProcessCommandOptions& o, const Plan& plan);
std::vector<correction::Correction> corrections_of(const Plan& plan, const Processed& p);

// Every output rendered (path, text), before any is written, and what goes
// to stdout and to the report when no JSON is written.
struct Rendered {
  std::vector<std::pair<std::string, std::string>> outputs;
  std::string stdout_text, json_for_report;
};

Rendered render(const ProcessCommandOptions& o, const Plan& plan, const Processed& p,
                const std::vector<correction::Correction>& corrections);
/// The HTML report drawn from the JSON (the --json file or a scratch copy).
int report_of(const ProcessCommandOptions& o, const std::string& json_text);

}  // namespace pdp
