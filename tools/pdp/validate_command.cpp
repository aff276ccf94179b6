#include "validate_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "awcc/atomic_output.hpp"
#include "awcc/json_text.hpp"
#include "awcc/random.hpp"
#include "study.hpp"
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
  cmd->add_option("--json", o.json, "write the results as JSON (keys in docs/output.md)");
}

namespace {

struct ErrorSeries {
  const char* name;
  std::vector<double> values;
};

}  // namespace

int run_validate(const ValidateOptions& o) {
  std::optional<synth::Scene> scene;
  StudyOptions study;
  try {
    scene = build_scene(o.scene);
    apply_method_options(o.methods, study);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  std::vector<RunResult> runs;
  try {
    Progress progress("validating");
    for (int i = 0; i < o.repeat; ++i) {
      synth::Scene s = *scene;
      if (o.repeat > 1) s.seed = awcc::derive_seed(scene->seed, static_cast<std::uint64_t>(i));
      runs.push_back(run_scene(s, study));
      progress(static_cast<double>(i + 1) / o.repeat);
    }
  } catch (const std::exception& e) {
    return report_error(e);
  }
  nlohmann::json j;
  if (runs.size() == 1) {
    fmt::print("{}", run_report(runs[0]));
    j = run_to_json(runs[0]);
  } else {
    std::vector<ErrorSeries> series{{"fscc velocity", {}}, {"fscc turbulence intensity", {}}, {"fscc d32", {}},
                                    {"awcc velocity", {}}, {"awcc turbulence intensity", {}}, {"awcc d32", {}},
                                    {"void fraction", {}}, {"bubble count rate", {}},
                                    {"window bias (m/s)", {}}, {"window rms (m/s)", {}}};
    std::int64_t fscc_undefined = 0, awcc_undefined = 0;
    for (const auto& r : runs) {
      const std::optional<double> e[] = {r.fscc_velocity.error(),  r.fscc_turbulence_intensity.error(),
                                         r.fscc_d32.error(),       r.awcc_velocity.error(),
                                         r.awcc_turbulence_intensity.error(), r.awcc_d32.error(),
                                         r.void_fraction_score.error(), r.count_rate_score.error(),
                                         r.window_bias,            r.window_rms};
      for (std::size_t k = 0; k < series.size(); ++k)
        if (e[k]) series[k].values.push_back(*e[k]);
      fscc_undefined += !r.fscc_velocity.value;
      awcc_undefined += !r.awcc_velocity.value;
    }
    fmt::print("{} runs of the scene (seeds derived from {}); relative errors (value / truth - 1):\n", runs.size(),
               scene->seed);
    fmt::print("{:<28}{:>8}{:>12}{:>24}\n", "error", "runs", "mean", "95 % interval");
    nlohmann::json summary = nlohmann::json::object();
    for (const auto& s : series) {
      const auto m = summarise95(s.values);
      const bool absolute = std::string(s.name).find("m/s") != std::string::npos;
      const double scale = absolute ? 1.0 : 100.0;
      const char* unit = absolute ? "" : " %";
      fmt::print("{:<28}{:>8}{:>10.3f}{}{:>14.3f}{} to {:.3f}{}\n", s.name, m.count, m.mean * scale, unit,
                 m.lower * scale, unit, m.upper * scale, unit);
      std::string key = s.name;
      for (auto& c : key) c = (c == ' ' ? '_' : c);
      key = key.substr(0, key.find("_(")).substr(0, key.find('('));
      summary[key] = {{"runs", m.count}, {"mean", m.mean}, {"ci95", {m.lower, m.upper}}};
    }
    if (fscc_undefined || awcc_undefined) {
      fmt::print("velocity undefined in {} FSCC and {} AWCC runs\n", fscc_undefined, awcc_undefined);
    }
    j["repeat"] = runs.size();
    j["error"] = summary;
    j["runs"] = nlohmann::json::array();
    for (const auto& r : runs) j["runs"].push_back(run_to_json(r));
    j["truth"] = j["runs"][0]["truth"];
    j["fscc"] = j["runs"][0].value("fscc", nlohmann::json());
    j["awcc"] = j["runs"][0].value("awcc", nlohmann::json());
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
