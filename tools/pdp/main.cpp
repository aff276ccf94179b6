// pdp: the dual-tip phase-detection probe toolkit's command line. Each
// subcommand is one source file: parse, call the libraries, print. Exit
// codes: command.hpp (the table of docs/guide/settings.md).
#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "awcc/memory.hpp"
#include "awcc/version.hpp"
#include "bench_command.hpp"
#include "command.hpp"
#include "compare_command.hpp"
#include "correct_command.hpp"
#include "score_command.hpp"
#include "design_command.hpp"
#include "process_command.hpp"
#include "report_command.hpp"
#include "sweep_command.hpp"
#include "synth_command.hpp"
#include "train_command.hpp"
#include "validate_command.hpp"

int main(int argc, char** argv) {
  // Logs go to stderr; results to files or stdout.
  spdlog::set_default_logger(spdlog::stderr_color_mt("pdp"));
  spdlog::set_pattern("%^[%l]%$ %v");
  pdp::set_command_line(argc, argv);
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

  struct Entry {
    pdp::Command command;
    std::function<int()> run;
    // Runs scene after scene on each thread (sweep, bench, design, validate):
    // freed memory is kept for the next scene rather than faulted in again
    // (awcc::keep_freed_memory). The other commands do one piece of work, for
    // which keeping it only raises the peak: `pdp process` of a 600 MB voltage
    // W64 peaked at 76 MB with it and 63 MB without, in the same time
    // (docs/performance.md, "Freed memory kept only where scenes repeat").
    bool scene_after_scene = false;
  };
  std::vector<Entry> commands(11);
  pdp::SynthOptions synth_options;
  pdp::setup_synth(app, commands[0].command, synth_options);
  commands[0].run = [&] { return pdp::run_synth(synth_options); };
  pdp::ProcessCommandOptions process_options;
  pdp::setup_process(app, commands[1].command, process_options);
  commands[1].run = [&] { return pdp::run_process(process_options); };
  pdp::ValidateOptions validate_options;
  pdp::setup_validate(app, commands[2].command, validate_options);
  commands[2].scene_after_scene = true;
  commands[2].run = [&] { return pdp::run_validate(validate_options); };
  pdp::CompareOptions compare_options;
  pdp::setup_compare(app, commands[3].command, compare_options);
  commands[3].run = [&] { return pdp::run_compare(compare_options); };
  pdp::SweepOptions sweep_options;
  pdp::setup_sweep(app, commands[4].command, sweep_options);
  commands[4].scene_after_scene = true;
  commands[4].run = [&] { return pdp::run_sweep(sweep_options); };
  pdp::BenchOptions bench_options;
  pdp::setup_bench(app, commands[5].command, bench_options);
  commands[5].scene_after_scene = true;
  commands[5].run = [&] { return pdp::run_bench(bench_options); };
  pdp::TrainCommandOptions train_options;
  pdp::setup_train(app, commands[6].command, train_options);
  commands[6].run = [&] { return pdp::run_train(train_options); };
  pdp::CorrectOptions correct_options;
  pdp::setup_correct(app, commands[7].command, correct_options);
  commands[7].run = [&] { return pdp::run_correct(correct_options); };
  pdp::ReportOptions report_options;
  pdp::setup_report(app, commands[8].command, report_options);
  commands[8].run = [&] { return pdp::run_report(report_options); };
  pdp::DesignOptions design_options;
  pdp::setup_design(app, commands[9].command, design_options);
  commands[9].scene_after_scene = true;
  commands[9].run = [&] { return pdp::run_design(design_options); };
  pdp::ScoreOptions score_options;
  pdp::setup_score(app, commands[10].command, score_options);
  commands[10].run = [&] { return pdp::run_score(score_options); };

  std::vector<std::string> arguments;
  try {
    arguments = pdp::arrange_arguments(app, std::vector<std::string>(argv + std::min(argc, 1), argv + argc));
  } catch (const std::exception& e) {
    return pdp::report_error(e);
  }
  try {
    std::reverse(arguments.begin(), arguments.end());  // CLI11 parses a reversed vector
    app.parse(arguments);
  } catch (const CLI::ParseError& e) {
    // Help and version are successes; every other parse error is bad usage.
    const int code = app.exit(e);
    return code == 0 ? pdp::exit_ok : pdp::exit_bad_usage;
  }
  for (auto& entry : commands) {
    if (!entry.command.app->parsed()) continue;
    try {
      pdp::finish_parsing(entry.command);
    } catch (const std::exception& e) {
      return pdp::report_error(e);
    }
    if (entry.scene_after_scene) awcc::keep_freed_memory();
    return entry.run();
  }
  return pdp::exit_bad_usage;
}
