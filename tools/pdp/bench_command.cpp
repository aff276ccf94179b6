#include "bench_command.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <sstream>
#include <spdlog/spdlog.h>

#include "awcc/atomic_output.hpp"
#include "awcc/units.hpp"
#include "correction/features.hpp"
#include "correction/model.hpp"
#include "study/bench.hpp"
#include "terminal.hpp"

namespace pdp {

void setup_bench(CLI::App& app, Command& command, BenchOptions& o) {
  auto* cmd = app.add_subcommand("bench", "Error against cost of every method and setting on fixed scenes, over seeds");
  command.app = cmd;
  add_config_option(command);
  command.required.push_back(
      path_option(cmd->add_option("-o,--output", o.output, "CSV: one row per scene, seed and setting")));
  cmd->add_option("--seeds", o.seeds, "seeds per scene; RMS error, bias and spread are over these")
      ->check(CLI::Range(1, 1000))->capture_default_str();
  cmd->add_option("--first-seed", o.first_seed, "the first seed")->capture_default_str();
  cmd->add_option("--scenes", o.scenes, "scenes: base, high-tu, small-bubbles, low-c, short-T")->capture_default_str();
  cmd->add_option("--durations", o.durations, "record lengths of the duration series (500 kHz, Np = 10), each 0.1s to 1h")
      ->capture_default_str();
  cmd->add_option("--duration", o.duration, "record length of the Np, fs and raw-voltage settings (0.1s to 1h)")
      ->capture_default_str();
  path_option(cmd->add_option("--correct", o.correct,
                              "correction model (.qrf): adds the corrected AWCC of every interval-path setting"));
  cmd->add_option("--threads", o.threads, "worker threads (0 = all cores); the numbers do not depend on it")
      ->check(CLI::Range(0, 4096))->capture_default_str();
  cmd->add_flag("--quick", o.quick, "short records, two seeds and few settings (for tests)");
}

namespace {

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(item);
  return out;
}

double record_length(const std::string& text, const std::string& option) {
  double d = 0.0;
  try {
    d = awcc::parse_quantity(text, awcc::Dimension::time);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("{}: {}", option, e.what()));
  }
  if (!(d >= 0.1 && d <= 3600.0)) throw std::invalid_argument(fmt::format("{} {}: give 0.1s to 1h", option, text));
  return d;
}

}  // namespace

int run_bench(const BenchOptions& o) {
  const std::vector<std::string> scenes = split(o.scenes);
  study::BenchPlan plan;
  std::optional<correction::CorrectionModel> model;
  int seeds = o.seeds;
  try {
    for (const auto& name : scenes) {
      try {
        (void)study::bench_scene(name);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(fmt::format("--scenes: {}", e.what()));
      }
    }
    plan.base_duration = record_length(o.duration, "--duration");
    plan.durations.clear();
    for (const auto& d : split(o.durations)) plan.durations.push_back(record_length(d, "--durations"));
    if (plan.durations.empty()) throw std::invalid_argument("--durations: give at least one record length");
    if (!o.correct.empty()) {
      model = correction::CorrectionModel::load(o.correct);
      if (const auto why = model->mismatch(correction::processing_of(awcc::AwccOptions{})); !why.empty()) {
        throw std::invalid_argument(fmt::format("--correct {}: the model was trained on results processed otherwise "
                                                "({}); pdp bench runs AWCC's defaults",
                                                o.correct, why));
      }
    }
  } catch (const std::exception& e) {
    return report_error(e);
  }
  if (o.quick) {
    plan.durations = {1.0, 2.0};
    plan.base_duration = std::min(plan.base_duration, 2.0);
    plan.nps = {5};
    plan.rates = {100e3};
    seeds = std::min(seeds, 2);
  }
  try {
    spdlog::info("pdp bench: {} scenes x {} seeds, {} records each", scenes.size(), seeds,
                 plan.durations.size() + plan.rates.size() + 1);
    Progress progress("benchmarking");
    const auto rows = study::run_bench(scenes, seeds, o.first_seed, plan, model ? &*model : nullptr, o.threads,
                                       [&](double fraction) { progress(fraction); });
    std::string out = study::bench_header();
    for (const auto& r : rows) out += study::bench_row_text(r);
    awcc::write_text_atomically(o.output, out);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
