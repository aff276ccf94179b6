#include "validate_command.hpp"

#include <fmt/format.h>

#include "awcc/atomic_output.hpp"
#include "awcc/json_text.hpp"
#include "awcc/options.hpp"
#include "study/multi_tip_validate.hpp"
#include "study/profile.hpp"
#include "study/validate.hpp"
#include "terminal.hpp"

namespace pdp {

void setup_validate(CLI::App& app, Command& command, ValidateOptions& o) {
  auto* cmd = app.add_subcommand("validate", "Synthesise a scene in memory, process it, compare with the truth");
  command.app = cmd;
  add_config_option(command);
  add_scene_options(cmd, o.scene);
  add_method_options(cmd, o.methods);
  o.bubbles.add(cmd, awcc::event_option_fields(), awcc::EventOptions{}, "Event detection (a probe of four or more tips)");
  o.bubbles.add(cmd, awcc::multi_tip_option_fields(), awcc::MultiTipOptions{}, "Multi-tip probes");
  cmd->add_option("--repeat", o.repeat, "runs with different seeds; means and 95 % intervals of every error")
      ->check(CLI::Range(1, 100000))->capture_default_str();
  path_option(cmd->add_option("--json", o.json, "write the results as JSON (keys in docs/output.md)"));
  add_mat_options(cmd, o.mat, "");
  path_option(cmd->add_option("--profile", o.profile,
                              "a synthetic profile (samples/stepped-profile.toml): every position synthesised and "
                              "processed, every profile quantity (Y90, C_mean, d, N, q_w, the model's D, ...) "
                              "against the truth it was made from; scene options given override its [scene]"));
  path_option(cmd->add_option("--correct", o.correct,
                              "with --profile: correct every position with this model (pdp process --correct), so "
                              "that each row contributes its corrected AWCC median"));
  o.flow.add(cmd, awcc::profile_flow_option_fields(), awcc::ProfileFlowOptions{}, "Profile quantities (--profile)",
             {"invert", "depth-levels", "flow-draws", "flow-seed"});
}

namespace {

// The results printed, the JSON and the MAT file written when asked (each
// under a temporary name): the exit status.
int finish(const ValidateOptions& o, const nlohmann::json& j) {
  try {
    if (!o.json.empty()) awcc::check_output_folder(o.json);
    if (!o.mat.path.empty()) awcc::check_output_folder(o.mat.path);
    if (!o.json.empty()) awcc::write_text_atomically(o.json, awcc::json_text(j));
    if (!o.mat.path.empty()) awcc::write_mat(o.mat.path, j, {}, o.mat.version());
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

// A probe of four or more tips: validated bubble by bubble
// (study/multi_tip_validate.hpp), the dual tip's FSCC and AWCC with the
// method options.
int run_multi_tip_validate(const synth::Scene& scene, const ValidateOptions& o) {
  study::MultiTipValidateOptions options;
  std::vector<study::MultiTipValidation> runs;
  try {
    apply_method_options(o.methods, options.dual);
    const auto settings = o.bubbles.settings();
    std::vector<bool> used(settings.size(), false);
    awcc::apply_settings(awcc::event_option_fields(), std::span<const awcc::OptionSetting>(settings), options.events,
                         used);
    awcc::apply_settings(awcc::multi_tip_option_fields(), std::span<const awcc::OptionSetting>(settings),
                         options.multi_tip, used);
    options.events.validate().throw_if_failed();
    options.multi_tip.validate().throw_if_failed();
    Progress progress("validating");
    runs = study::validate_multi_tip_repeats(scene, options, o.repeat, [&](double fraction) { progress(fraction); });
  } catch (const std::exception& e) {
    return report_error(e);
  }
  nlohmann::json j;
  if (runs.size() == 1) {
    fmt::print("{}", study::multi_tip_report(runs[0]));
    j = study::multi_tip_to_json(runs[0]);
  } else {
    const auto summary = study::summarise_multi_tip(runs);
    fmt::print("{}", study::multi_tip_repeats_report(runs, summary, scene.seed));
    j = study::multi_tip_repeats_to_json(runs, summary);
  }
  return finish(o, j);
}

// A synthetic profile: every position processed, the profile quantities
// against their truth (study/profile.hpp).
int run_profile_validate(const ValidateOptions& o) {
  study::ProfileValidation v;
  try {
    if (o.repeat != 1) throw awcc::OptionError("--repeat: a profile is validated once (its positions have their seeds)", "repeat");
    if (!o.bubbles.settings().empty()) {
      throw awcc::OptionError(fmt::format("--{}: a profile's positions are processed as tip pairs",
                                          o.bubbles.settings().front().name),
                              o.bubbles.settings().front().name);
    }
    const auto spec = build_profile(o.profile, o.scene);
    study::ProfileValidateOptions options;
    apply_method_options(o.methods, options.run);
    options.flow = awcc::profile_flow_options(o.flow.settings());
    std::optional<correction::CorrectionModel> model;
    if (!o.correct.empty()) {
      model = correction::CorrectionModel::load(o.correct);
      if (const auto why = model->mismatch(correction::processing_of(options.run.awcc)); !why.empty()) {
        throw awcc::OptionError(fmt::format("--correct {}: the model was trained on results processed otherwise ({})",
                                            o.correct, why),
                                "correct");
      }
      options.correction = &*model;
    }
    Progress progress("validating the profile");
    v = study::validate_profile(spec, options, [&](double fraction) { progress(fraction); });
  } catch (const std::exception& e) {
    return report_error(e);
  }
  fmt::print("{}", v.report());
  return finish(o, study::profile_validation_json(v));
}

}  // namespace

int run_validate(const ValidateOptions& o) {
  if (!o.profile.empty()) return run_profile_validate(o);
  if (!o.correct.empty()) {
    return report_error(awcc::OptionError("--correct: pdp validate corrects a --profile's positions; a scene's run is "
                                          "scored uncorrected (pdp sweep and pdp train study the correction)",
                                          "correct"));
  }
  if (!o.flow.settings().empty()) {
    return report_error(awcc::OptionError(
        fmt::format("--{}: the profile quantities' options apply to --profile", o.flow.settings().front().name),
        o.flow.settings().front().name));
  }
  synth::Scene scene;
  try {
    scene = build_scene(o.scene);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  if (scene.probe_tips().size() >= 4) return run_multi_tip_validate(scene, o);
  if (!o.bubbles.settings().empty()) {
    return report_error(awcc::OptionError(
        fmt::format("--{}: event detection's and the multi-tip options apply to a scene of four or more tips; this "
                    "scene has {}",
                    o.bubbles.settings().front().name, scene.probe_tips().size()),
        o.bubbles.settings().front().name));
  }
  study::RunOptions options;
  std::vector<study::RunResult> runs;
  try {
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
  return finish(o, j);
}

}  // namespace pdp
