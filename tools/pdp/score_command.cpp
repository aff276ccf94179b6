#include "score_command.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <filesystem>

#include "awcc/atomic_output.hpp"
#include "awcc/errors.hpp"
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
  cmd->add_option("--truth", o.truth,
                  "score against the realised statistics of each run (what pdp trains on) or the imposed scene "
                  "parameters (other simulators' truth): realised | imposed")
      ->check(CLI::IsMember({"realised", "imposed"}))
      ->capture_default_str();
  cmd->add_flag("--other-processing", o.other_processing,
                "score runs processed otherwise than the model's training data (another AWCC convention); the "
                "report names the difference");
  cmd->add_flag("--as-peer-rows", o.as_peer_rows,
                "score the runs as a peer's file states them (u, u_rms, c, d32, dx, dy, Np: fs, duration, windows "
                "and the time-scale ratio removed), so that the model's reduced forest corrects them");
}

int run_score(const ScoreOptions& o) {
  try {
    const auto model = correction::CorrectionModel::load(o.model);
    const std::vector<std::filesystem::path> csvs(o.sweeps.begin(), o.sweeps.end());
    const auto truth = correction::truth_kind_of(o.truth).value_or(correction::TruthKind::realised);
    auto set = correction::load_training_set(csvs, model.min_windows, truth);
    if (o.as_peer_rows) set.rows = correction::as_peer_rows(std::move(set.rows));
    std::string processed_otherwise;
    if (o.other_processing) {
      processed_otherwise = model.mismatch(set.processing);
    } else {
      correction::require_model_processing(model, set);
    }
    if (set.processing_assumed) {
      spdlog::warn("the sweep CSVs do not record how AWCC was processed; assumed as the model's");
    }
    if (set.generator_versions.size() > 1) {
      spdlog::warn("the sweep CSVs mix runs of generator versions {}", fmt::join(set.generator_versions, " and "));
    }
    std::vector<correction::HeldOutPrediction> predictions;
    const auto scores = correction::score(model, set.rows, &predictions, o.threads);
    if (scores.rows == 0) {
      // Scores of no run are no scores: refused, not printed as zeros.
      throw awcc::InputError(fmt::format(
          "{}: none of the {} runs with at least {} accepted windows could be scored by {}: each is outside the "
          "model's training ranges or lacks a feature it takes{}",
          fmt::join(o.sweeps, ", "), set.rows.size(), model.min_windows, std::filesystem::path(o.model).filename().string(),
          o.as_peer_rows && !model.reduced
              ? " (--as-peer-rows removes fs, duration and the windows, and this model has no reduced forest for such "
                "rows: train it with --reduced on)"
              : ""));
    }
    std::string sources;
    for (const auto& s : set.sources) sources += (sources.empty() ? "" : ", ") + s;
    std::string report = fmt::format(
        "pdp score {}: {} (generator version {}); {} runs read, {} with at least {} accepted windows; scored {} "
        "({} outside the training ranges, not scored; {} of the scored untrusted by the trust rules: {} outside the "
        "envelope, {} multimodal, {} at a lag of one sample, {} at a chance yield; the Tu of {} not corrected: "
        "bubbles far larger than dx)\n",
        std::filesystem::path(o.model).filename().string(), sources, fmt::join(set.generator_versions, " and "),
        set.total, set.rows.size(), model.min_windows, scores.rows, scores.out_of_range, scores.untrusted,
        scores.outside_envelope, scores.multimodal, scores.one_sample_lag, scores.chance_yield, scores.large_bubbles);
    report += fmt::format("truth: {}{}\n", o.truth,
                          truth == correction::TruthKind::imposed ? " (the scene's velocity and tu)" : " (the run's realised statistics)");
    if (!processed_otherwise.empty()) {
      report += fmt::format("processed otherwise than the model's training data: {}\n", processed_otherwise);
    }
    if (o.as_peer_rows) report += "as peers' rows: fs, duration, windows and the time-scale ratio removed\n";
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
