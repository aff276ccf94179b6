#include "train_command.hpp"

#include <fmt/format.h>
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
      cmd->add_option("sweeps", o.sweeps, "pdp sweep CSVs (Monte Carlo over the ranges the model must cover)")
          ->check(CLI::ExistingFile));
  command.required.push_back(cmd->add_option("-o,--output", o.output, "model file to write (.qrf)"));
  cmd->add_option("--trees", o.trees, "trees per forest")->check(CLI::Range(1, 100000))->capture_default_str();
  cmd->add_option("--min-windows", o.min_windows, "runs with fewer accepted AWCC windows are left out (and counted)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 40))->capture_default_str();
  cmd->add_option("--held-out", o.held_out, "fraction of runs held out for the report (not trained on)")
      ->check(CLI::Range(0.01, 0.99))->capture_default_str();
  cmd->add_option("--folds", o.folds, "cross-validation folds over the hyperparameter grids; 0 = none (first grid values)")
      ->check(CLI::Range(0, 100))->capture_default_str();
  cmd->add_option("--cv-trees", o.cv_trees, "trees per forest during cross-validation")->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--min-leaf", o.min_leaf_grid, "least training draws per leaf: the values tried")->capture_default_str();
  cmd->add_option("--features-per-split", o.features_per_split_grid, "features tried per split (1-7): the values tried")
      ->capture_default_str();
  cmd->add_option("--seed", o.seed, "seed of the split, the folds and the forests")->capture_default_str();
  cmd->add_option("--threads", o.threads, "threads (0 = all cores)")->check(CLI::Range(0, 4096))->capture_default_str();
  cmd->add_option("--predictions", o.predictions, "write the held-out predictions as CSV");
  cmd->add_option("--learning-curve", o.learning_curve, "write the held-out scores against training runs as CSV");
  cmd->add_option("--report", o.report, "write the report to this file too");
}

namespace {

std::vector<int> int_list(const std::string& text, const char* option) {
  std::vector<int> out;
  for (const auto& item : awcc::split_cells(text)) {
    const auto v = awcc::cell_number(item);
    if (!v || *v < 1 || *v != std::floor(*v) || *v > 1e6) {
      throw std::invalid_argument(fmt::format("{} '{}': give positive whole numbers separated by commas, e.g. 5,10,20",
                                              option, text));
    }
    out.push_back(static_cast<int>(*v));
  }
  return out;
}

}  // namespace

int run_train(const TrainCommandOptions& o) {
  correction::TrainOptions t;
  try {
    t.trees = o.trees;
    t.min_windows = o.min_windows;
    t.held_out = o.held_out;
    t.folds = o.folds;
    t.cv_trees = o.cv_trees;
    t.min_leaf_grid = int_list(o.min_leaf_grid, "--min-leaf");
    t.features_per_split_grid = int_list(o.features_per_split_grid, "--features-per-split");
    for (int f : t.features_per_split_grid) {
      if (f > correction::Features::count) {
        throw std::invalid_argument(fmt::format("--features-per-split {}: there are {} features", f,
                                                correction::Features::count));
      }
    }
    t.min_leaf = t.min_leaf_grid.front();
    t.features_per_split = t.features_per_split_grid.front();
    t.seed = o.seed;
    t.threads = o.threads;
    if (auto why = t.validate(); !why.empty()) throw std::invalid_argument(why);
  } catch (const std::invalid_argument& e) {
    return report_error(e);
  }
  try {
    std::vector<std::filesystem::path> csvs(o.sweeps.begin(), o.sweeps.end());
    const auto set = correction::load_training_set(csvs, t.min_windows);
    spdlog::info("{} runs read, {} used: {} failed, {} without an AWCC velocity, {} with fewer than {} accepted windows",
                 set.total, set.rows.size(), set.excluded_error, set.excluded_undefined, set.excluded_windows,
                 t.min_windows);
    Progress progress("training");
    const auto result = correction::train_model(set, t, [&](double f) { progress(f); });
    result.model.save(o.output);
    if (!o.predictions.empty()) awcc::write_text_atomically(o.predictions, correction::predictions_csv(result.predictions));
    if (!o.learning_curve.empty()) awcc::write_text_atomically(o.learning_curve, correction::learning_curve_csv(result.learning_curve));
    const auto report = result.report();
    if (!o.report.empty()) awcc::write_text_atomically(o.report, report);
    fmt::print("{}", report);
    spdlog::info("{}: written ({:.1f} MB)", o.output, static_cast<double>(std::filesystem::file_size(o.output)) / 1e6);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
