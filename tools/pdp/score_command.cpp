#include "score_command.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <filesystem>

#include "awcc/atomic_output.hpp"
#include "correction/model.hpp"
#include "correction/training.hpp"

namespace pdp {

void setup_score(CLI::App& app, Command& command, ScoreOptions& o) {
  auto* cmd = app.add_subcommand("score", "Score a trained correction model on sweep runs it was not trained on");
  command.app = cmd;
  add_config_option(command);
  command.required.push_back(
      path_option(cmd->add_option("-m,--model", o.model, "correction model (.qrf, from pdp train)"))
          ->check(CLI::ExistingFile));
  command.required.push_back(
      path_option(cmd->add_option("sweeps", o.sweeps, "pdp sweep CSVs (runs the model was not trained on)"))
          ->check(CLI::ExistingFile));
  path_option(cmd->add_option("--predictions", o.predictions, "write the predictions as CSV"));
  path_option(cmd->add_option("--report", o.report, "write the report to this file too"));
  cmd->add_option("--threads", o.threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 4096));
}

int run_score(const ScoreOptions& o) {
  try {
    const auto model = correction::CorrectionModel::load(o.model);
    const std::vector<std::filesystem::path> csvs(o.sweeps.begin(), o.sweeps.end());
    const auto set = correction::load_training_set(csvs, model.min_windows);
    correction::require_model_processing(model, set);
    if (set.processing_assumed) {
      spdlog::warn("the sweep CSVs do not record how AWCC was processed; assumed as the model's");
    }
    if (set.generator_versions.size() > 1) {
      spdlog::warn("the sweep CSVs mix runs of generator versions {}", fmt::join(set.generator_versions, " and "));
    }
    std::vector<correction::HeldOutPrediction> predictions;
    const auto scores = correction::score(model, set.rows, &predictions, o.threads);
    std::string sources;
    for (const auto& s : set.sources) sources += (sources.empty() ? "" : ", ") + s;
    std::string report = fmt::format(
        "pdp score {}: {} (generator version {}); {} runs read, {} with at least {} accepted windows; scored {} "
        "({} outside the training ranges, not scored; {} of the scored untrusted by the trust rules: {} outside the "
        "envelope, {} multimodal)\n",
        std::filesystem::path(o.model).filename().string(), sources, fmt::join(set.generator_versions, " and "),
        set.total, set.rows.size(), model.min_windows, scores.rows, scores.out_of_range, scores.untrusted,
        scores.outside_envelope, scores.multimodal);
    report += correction::scores_report(scores, predictions);
    if (!o.predictions.empty()) awcc::check_output_folder(o.predictions);
    if (!o.report.empty()) awcc::check_output_folder(o.report);
    if (!o.predictions.empty()) awcc::write_text_atomically(o.predictions, correction::predictions_csv(predictions));
    if (!o.report.empty()) awcc::write_text_atomically(o.report, report);
    fmt::print("{}", report);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
