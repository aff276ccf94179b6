#pragma once
// The steps of pdp process (process_command.cpp runs them in turn): the plan
// made before any recording is read (process_plan.cpp), the recordings
// processed and corrected (process_files.cpp), every output rendered before
// any is written (process_render.cpp).

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "awcc/mat_output.hpp"
#include "awcc/process.hpp"
#include "awcc/profile_flow.hpp"
#include "correction/model.hpp"
#include "process_command.hpp"
#include "study/profile_run.hpp"

namespace pdp {

// Everything decided before the first recording is read.
struct Plan {
  awcc::ProcessOptions options;
  std::vector<std::optional<double>> positions;
  std::optional<correction::CorrectionModel> model;
  awcc::ProfileFlowOptions flow;  ///< a profile's flow quantities
};

Plan plan_of(const ProcessCommandOptions& o);

// The recordings processed (study::process_profile), corrected when a model
// is given, with the profile's flow.
study::ProfileRun process_files(const ProcessCommandOptions& o, const Plan& plan);

// Every output rendered (path, text), before any is written, and what goes
// to stdout and to the report when no JSON is written.
struct Rendered {
  std::vector<std::pair<std::string, std::string>> outputs;
  std::string stdout_text, json_for_report;
  /// --mat: the JSON's content and the tables (awcc/mat_output.hpp).
  struct Mat {
    std::string path;
    nlohmann::json document;
    std::vector<awcc::MatTable> tables;
    awcc::MatVersion version = awcc::MatVersion::v5;
  };
  std::optional<Mat> mat;
};

Rendered render(const ProcessCommandOptions& o, const Plan& plan, const study::ProfileRun& run);
/// The HTML report drawn from the JSON (the --json file or a scratch copy).
int report_of(const ProcessCommandOptions& o, const std::string& json_text);

}  // namespace pdp
