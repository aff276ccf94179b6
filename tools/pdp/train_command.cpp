#include "train_command.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <cmath>


#include "awcc/atomic_output.hpp"
#include "awcc/csv.hpp"
#include "correction/training.hpp"
#include "terminal.hpp"

namespace pdp {

void setup_train(CLI::App& app, Command& command, TrainCommandOptions& o) {
  auto* cmd = app.add_subcommand("train", "Train the bias-correction model (quantile regression forests) on sweep CSVs");
  command.app = cmd;
  add_config_option(command);
  command.required.push_back(
      path_option(
          cmd->add_option("sweeps", o.sweeps, "pdp sweep CSVs (Monte Carlo over the ranges the model must cover)"))
          ->check(CLI::ExistingFile));
  command.required.push_back(path_option(cmd->add_option("-o,--output", o.output, "model file to write (.qrf)")));
  o.training.add(cmd, correction::training_option_fields(), correction::TrainOptions{}, "Training");
  path_option(cmd->add_option("--predictions", o.predictions, "write the held-out predictions as CSV"));
  path_option(
      cmd->add_option("--learning-curve", o.learning_curve, "write the held-out scores against training runs as CSV"));
  path_option(cmd->add_option("--report", o.report, "write the report to this file too"));
  path_option(
      cmd->add_option("--compare-model", o.compare_model,
                      "another model (e.g. the one shipped before) scored on the same held-out runs, band by band"))
      ->check(CLI::ExistingFile);
  cmd->add_option("--envelope-of", o.envelope_of,
                  "a trained model: instead of training, measure the envelopes of its trust rule (a) on the sweeps' "
                  "runs (its training distribution with other seeds: runs it was not trained on) and write it with "
                  "them")
      ->check(CLI::ExistingFile);
}

namespace {

// Rows of two generator versions share their statistics by design (awcc/random.hpp) but not their scenes.
void say_generator_versions(const correction::TrainingSet& set) {
  if (set.generator_versions.size() > 1) {
    spdlog::warn("the sweep CSVs mix runs of generator versions {}: their statistics are the same by design, a "
                 "seed gives a different scene in each; the model's provenance records both",
                 fmt::join(set.generator_versions, " and "));
  }
}

int run_envelope(const TrainCommandOptions& o, const correction::TrainOptions& t) {
  const auto model = correction::CorrectionModel::load(o.envelope_of);
  std::vector<std::filesystem::path> csvs(o.sweeps.begin(), o.sweeps.end());
  const auto set = correction::load_training_set(csvs, model.min_windows);
  say_generator_versions(set);
  const auto result = correction::measure_trust(model, set, t);
  awcc::check_output_folder(o.output);
  if (!o.report.empty()) awcc::check_output_folder(o.report);
  result.model.save(o.output);
  if (!o.report.empty()) awcc::write_text_atomically(o.report, result.summary + "\n");
  fmt::print("{}\n", result.summary);
  return exit_ok;
}

}  // namespace


int run_train(const TrainCommandOptions& o) {
  correction::TrainOptions t;
  try {
    const auto settings = o.training.settings();
    std::vector<bool> used(settings.size(), false);
    awcc::apply_settings(correction::training_option_fields(), std::span<const awcc::OptionSetting>(settings), t, used);
    t.validate().throw_if_failed();
  } catch (const std::invalid_argument& e) {
    return report_error(e);
  }
  try {
    if (!o.envelope_of.empty()) return run_envelope(o, t);
    std::vector<std::filesystem::path> csvs(o.sweeps.begin(), o.sweeps.end());
    const auto set = correction::load_training_set(csvs, t.min_windows);
    say_generator_versions(set);
    spdlog::info("{} runs read, {} used: {} failed, {} without an AWCC velocity, {} with fewer than {} accepted windows",
                 set.total, set.rows.size(), set.excluded_error, set.excluded_undefined, set.excluded_windows,
                 t.min_windows);
    Progress progress("training");
    const auto result = correction::train_model(set, t, [&](double f) { progress(f); });
    // Every output's folder is checked before any is written.
    auto report = result.report();
    if (!o.compare_model.empty()) {
      const auto other = correction::CorrectionModel::load(o.compare_model);
      std::vector<correction::TrainingRow> rows;
      for (const auto& p : result.predictions) rows.push_back(p.row);
      std::vector<correction::HeldOutPrediction> theirs;
      correction::score(other, rows, &theirs, t.threads);
      report += correction::comparison_report(result.predictions, theirs,
                                              std::filesystem::path(o.compare_model).filename().string());
    }
    std::vector<std::pair<std::string, std::string>> texts;
    if (!o.predictions.empty()) texts.emplace_back(o.predictions, correction::predictions_csv(result.predictions));
    if (!o.learning_curve.empty()) texts.emplace_back(o.learning_curve, correction::learning_curve_csv(result.learning_curve));
    if (!o.report.empty()) texts.emplace_back(o.report, report);
    awcc::check_output_folder(o.output);
    for (const auto& [path, text] : texts) awcc::check_output_folder(path);
    result.model.save(o.output);
    for (const auto& [path, text] : texts) awcc::write_text_atomically(path, text);
    fmt::print("{}", report);
    spdlog::info("{}: written ({:.1f} MB)", o.output, static_cast<double>(std::filesystem::file_size(o.output)) / 1e6);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
