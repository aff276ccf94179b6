#include "correct_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <set>
#include <sstream>

#include "awcc/atomic_output.hpp"
#include "awcc/awcc.hpp"
#include "awcc/errors.hpp"
#include "awcc/json_text.hpp"
#include "awcc/options.hpp"
#include "awcc/read_back.hpp"
#include "awcc/serialise.hpp"
#include "awcc/units.hpp"
#include "correction/profile_rows.hpp"
#include "correction/rows.hpp"

namespace pdp {

void setup_correct(CLI::App& app, Command& command, CorrectOptions& o) {
  auto* cmd = app.add_subcommand("correct", "Add bias-corrected velocity and Tu quantiles to a pdp process JSON or profile CSV");
  command.app = cmd;
  add_config_option(command);
  command.required.push_back(
      path_option(cmd->add_option("input", o.input, "pdp process JSON (one recording or a profile) or profile CSV"))
          ->check(CLI::ExistingFile));
  command.required.push_back(
      path_option(cmd->add_option("-m,--model", o.model,
                                  "correction model (.qrf, from pdp train; samples/model/awcc.qrf ships)"))
          ->check(CLI::ExistingFile));
  path_option(cmd->add_option("-o,--output", o.output, "output file (same format as the input) [default: stdout]"));
  add_mat_options(cmd, o.mat, "profile_table (a profile; a JSON input)");
  cmd->add_option("--dx", o.dx, "streamwise tip separation, m (units allowed), where the input has none");
  cmd->add_option("--dy", o.dy, "lateral tip separation, m (units allowed), where the input has none");
  cmd->add_option("--np", o.np, "AWCC particles per window, where the input has none")->check(CLI::Range(awcc::np_min, awcc::np_max));
  cmd->add_option("--fs", o.fs, "sampling rate, Hz (units allowed), where the input has none (extended models)");
  cmd->add_option("--duration", o.duration, "record length, s (units allowed), where the input has none (extended models)");
  cmd->add_option("--weighting", o.weighting,
                  "how the input's AWCC moments were taken, where it does not record it: duration | none (a model "
                  "with the weighting feature; not given: both answers mixed)")
      ->check(CLI::IsMember({"duration", "none"}));
  o.flow.add(cmd, awcc::profile_flow_option_fields(), awcc::ProfileFlowOptions{},
             "Profile quantities (a profile with positions: Y90, C_mean, discharge, models, with the corrected velocities)");
}

int run_correct(const CorrectOptions& o) {
  correction::RowDefaults defaults;
  try {
    auto length = [](const std::string& text, const char* flag) {
      try {
        return awcc::parse_quantity(text, awcc::Dimension::length);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(fmt::format("{}: {}", flag, e.what()));
      }
    };
    if (!o.dx.empty()) defaults.dx = length(o.dx, "--dx");
    if (!o.dy.empty()) defaults.dy = length(o.dy, "--dy");
    if (o.np > 0) defaults.np = o.np;
    auto positive = [](const std::string& text, awcc::Dimension dimension, const char* flag) {
      double v = 0.0;
      try {
        v = awcc::parse_quantity(text, dimension);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(fmt::format("{}: {}", flag, e.what()));
      }
      if (!(v > 0.0)) throw std::invalid_argument(fmt::format("{}: {} must be positive", flag, text));
      return v;
    };
    if (!o.fs.empty()) defaults.fs = positive(o.fs, awcc::Dimension::frequency, "--fs");
    if (!o.duration.empty()) defaults.duration = positive(o.duration, awcc::Dimension::time, "--duration");
    if (!o.weighting.empty()) {
      defaults.weighting = o.weighting == "none" ? awcc::Weighting::none : awcc::Weighting::duration;
    }
    if (!o.output.empty() && std::filesystem::exists(o.output) &&
        (std::filesystem::equivalent(o.output, o.input) || std::filesystem::equivalent(o.output, o.model))) {
      throw std::invalid_argument(fmt::format("{} is an input; choose another output file", o.output));
    }
    if (!o.mat.path.empty() && std::filesystem::exists(o.mat.path) &&
        (std::filesystem::equivalent(o.mat.path, o.input) || std::filesystem::equivalent(o.mat.path, o.model))) {
      throw std::invalid_argument(fmt::format("--mat {} is an input; choose another output file", o.mat.path));
    }
    const auto model = correction::CorrectionModel::load(o.model);
    std::ifstream in(o.input, std::ios::binary);
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string text = buffer.str();
    const auto first = text.find_first_not_of(" \t\r\n");
    const bool json = first != std::string::npos && (text[first] == '{' || text[first] == '[');
    if (!o.mat.path.empty() && !json) {
      // A CSV's rows stay a CSV (MATLAB's readtable reads it); the MAT file
      // holds a JSON's tree, which a CSV does not have.
      throw awcc::OptionError(fmt::format("--mat: {} is a profile CSV; --mat needs the JSON of pdp process --json "
                                          "(or read the corrected CSV with MATLAB's readtable)",
                                          o.input),
                              "mat");
    }
    const std::string model_name = std::filesystem::path(o.model).filename().string();
    const auto flow_options = awcc::profile_flow_options(o.flow.settings());
    auto out = json ? correction::correct_process_json(model, text, defaults, o.input, model_name)
                    : correction::correct_profile_csv(model, text, defaults, o.input);
    // The profile's flow with the corrected velocities, read back from the
    // corrected file: the rows a later reader of it gets.
    std::optional<awcc::ProfileFlowResult> flow;
    nlohmann::json corrected;
    if (json) corrected = nlohmann::json::parse(out.text);
    const auto read = json ? correction::profile_rows_of_json(corrected, o.input)
                           : correction::profile_rows_of_csv(out.text, o.input);
    if (read.why_none.empty()) {
      flow = correction::profile_flow_of(read.rows, flow_options);
      if (json) {
        corrected[awcc::process_key::flow] = awcc::to_json(*flow);
        out.text = awcc::json_text(corrected);
      }
    } else if (!o.flow.settings().empty()) {
      const std::string name = o.flow.settings().front().name;
      throw awcc::OptionError(fmt::format("--{}: a profile's flow quantities need two or more recordings with their "
                                          "positions: {}",
                                          name, read.why_none),
                              name);
    }
    // One line per distinct warning (a profile repeats them row by row).
    for (const auto& w : std::set<std::string>(out.warnings.begin(), out.warnings.end())) spdlog::warn("{}", w);
    if (flow) {
      for (const auto& w : flow->warnings()) spdlog::warn("{}", w);
    }
    if (!o.output.empty()) awcc::check_output_folder(o.output);
    if (!o.mat.path.empty()) {
      awcc::check_output_folder(o.mat.path);
      const auto document = nlohmann::json::parse(out.text);
      awcc::write_mat(o.mat.path, document, profile_mat_tables(document), o.mat.version());
    }
    if (o.output.empty()) {
      fmt::print("{}", out.text);
    } else {
      awcc::write_text_atomically(o.output, out.text);
      // stdout holds no table: the profile's flow quantities are read there.
      if (flow) fmt::print("{}", flow->report());
    }
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
