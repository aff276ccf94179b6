#include "validate_command.hpp"

#include <fmt/format.h>

#include "awcc/atomic_output.hpp"
#include "awcc/json_text.hpp"
#include "study/validate.hpp"
#include "terminal.hpp"

namespace pdp {

void setup_validate(CLI::App& app, Command& command, ValidateOptions& o) {
  auto* cmd = app.add_subcommand("validate", "Synthesise a scene in memory, process it, compare with the truth");
  command.app = cmd;
  add_config_option(command);
  add_scene_options(cmd, o.scene);
  add_method_options(cmd, o.methods);
  cmd->add_option("--repeat", o.repeat, "runs with different seeds; means and 95 % intervals of every error")
      ->check(CLI::Range(1, 100000))->capture_default_str();
  path_option(cmd->add_option("--json", o.json, "write the results as JSON (keys in docs/output.md)"));
}

int run_validate(const ValidateOptions& o) {
  synth::Scene scene;
  study::RunOptions options;
  std::vector<study::RunResult> runs;
  try {
    scene = build_scene(o.scene);
    apply_method_options(o.methods, options);
    Progress progress("validating");
    runs = study::run_repeats(scene, options, o.repeat, [&](double fraction) { progress(fraction); });
  } catch (const std::exception& e) {
    return report_error(e);
  }
  nlohmann::json j;
  if (runs.size() == 1) {
    fmt::print("{}", study::run_report(runs[0]));
    j = study::run_to_json(runs[0]);
  } else {
    const auto summary = study::summarise_runs(runs);
    fmt::print("{}", study::repeats_report(runs, summary, scene.seed));
    j = study::repeats_to_json(runs, summary);
  }
  if (!o.json.empty()) {
    try {
      awcc::write_text_atomically(o.json, awcc::json_text(j));
    } catch (const std::exception& e) {
      return report_error(e);
    }
  }
  return exit_ok;
}

}  // namespace pdp
