// pdp: the dual-tip phase-detection probe toolkit's command line.
#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "awcc/version.hpp"
#include "bench_command.hpp"
#include "compare_command.hpp"
#include "correct_command.hpp"
#include "process_command.hpp"
#include "sweep_command.hpp"
#include "synth_command.hpp"
#include "train_command.hpp"
#include "validate_command.hpp"

int main(int argc, char** argv) {
  // Logs go to stderr; results to files or stdout.
  spdlog::set_default_logger(spdlog::stderr_color_mt("pdp"));
  spdlog::set_pattern("%^[%l]%$ %v");

  CLI::App app{"pdp: dual-tip phase-detection probe toolkit (AWCC processing, synthetic probe)"};
#ifdef PDP_WITH_MPI
  app.set_version_flag("--version", std::string("pdp ") + awcc::version + " (MPI)");
#else
  app.set_version_flag("--version", std::string("pdp ") + awcc::version);
#endif
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace | debug | info | warn | error | off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  app.parse_complete_callback([&]() { spdlog::set_level(spdlog::level::from_str(log_level)); });
  app.require_subcommand(1);

  pdp::SynthOptions synth_options;
  auto* synth_command = pdp::setup_synth(app, synth_options);
  pdp::ProcessCommandOptions process_options;
  auto* process_command = pdp::setup_process(app, process_options);
  pdp::ValidateOptions validate_options;
  auto* validate_command = pdp::setup_validate(app, validate_options);
  pdp::CompareOptions compare_options;
  auto* compare_command = pdp::setup_compare(app, compare_options);
  pdp::SweepOptions sweep_options;
  auto* sweep_command = pdp::setup_sweep(app, sweep_options);
  pdp::BenchOptions bench_options;
  auto* bench_command = pdp::setup_bench(app, bench_options);
  pdp::TrainCommandOptions train_options;
  auto* train_command = pdp::setup_train(app, train_options);
  pdp::CorrectOptions correct_options;
  auto* correct_command = pdp::setup_correct(app, correct_options);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (synth_command->parsed()) return pdp::run_synth(synth_options);
  if (process_command->parsed()) return pdp::run_process(process_options);
  if (validate_command->parsed()) return pdp::run_validate(validate_options);
  if (compare_command->parsed()) return pdp::run_compare(compare_options);
  if (sweep_command->parsed()) return pdp::run_sweep(sweep_options);
  if (bench_command->parsed()) return pdp::run_bench(bench_options);
  if (train_command->parsed()) return pdp::run_train(train_options);
  if (correct_command->parsed()) return pdp::run_correct(correct_options);
  return 0;
}
