#include "scene_cli.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "awcc/units.hpp"
#include "study.hpp"

namespace pdp {

void add_scene_options(CLI::App* cmd, SceneCli& cli) {
  cmd->add_option("--config", cli.config, "scene TOML file; command-line fields override it")->check(CLI::ExistingFile);
  const synth::Scene defaults;
  const auto fields = synth::scene_fields();
  cli.values.resize(fields.size());
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const auto& f = fields[i];
    auto* opt = cmd->add_option(fmt::format("--{}", f.name), cli.values[i],
                                fmt::format("{} [default: {}]", f.help, f.format(defaults)));
    opt->group("Scene (same names in the TOML file; units allowed, e.g. 5mm, 500kHz, 300s)");
    cli.options.push_back(opt);
  }
}

std::optional<synth::Scene> build_scene(const SceneCli& cli) {
  synth::Scene scene;
  if (!cli.config.empty()) {
    try {
      synth::load_scene_toml(cli.config, scene);
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
      return std::nullopt;
    }
  }
  const auto fields = synth::scene_fields();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (cli.options[i]->count() == 0) continue;
    try {
      fields[i].parse(scene, cli.values[i]);
    } catch (const std::exception& e) {
      spdlog::error("--{}: {}", fields[i].name, e.what());
      return std::nullopt;
    }
  }
  if (const auto errors = scene.validate(); !errors.empty()) {
    spdlog::error("invalid scene (from {}):", cli.config.empty() ? "the command line" : cli.config + " and the command line");
    for (const auto& e : errors) spdlog::error("  {}", e);
    return std::nullopt;
  }
  return scene;
}

void add_method_options(CLI::App* cmd, MethodCli& m) {
  const char* g = "Methods";
  cmd->add_option("--np", m.np, "AWCC particles per window")->check(CLI::Range(1, 1000))->capture_default_str()->group(g);
  cmd->add_option("--filter-a", m.filter_a, "AWCC correlation filter threshold A")->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()->group(g);
  cmd->add_option("--roc", m.roc, "AWCC robust outlier cutoff: on | off")->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str()->group(g);
  cmd->add_option("--weighting", m.weighting, "AWCC moments: duration | none")
      ->check(CLI::IsMember({"duration", "none"}))->capture_default_str()->group(g);
  cmd->add_option("--subsample", m.subsample, "peak refinement: none | parabolic")
      ->check(CLI::IsMember({"none", "parabolic"}))->capture_default_str()->group(g);
  cmd->add_option("--path", m.path, "AWCC correlation path: intervals | fft")
      ->check(CLI::IsMember({"intervals", "fft"}))->capture_default_str()->group(g);
  cmd->add_option("--max-lag", m.max_lag, "FSCC lags searched, s")->capture_default_str()->group(g);
  cmd->add_option("--segments", m.segments, "FSCC segments (1 = full record)")->check(CLI::Range(1, 1000))
      ->capture_default_str()->group(g);
}

void apply_method_options(const MethodCli& m, StudyOptions& o) {
  o.awcc.np = m.np;
  o.awcc.filter_a = m.filter_a;
  o.awcc.roc = m.roc == "on";
  o.awcc.weighting = m.weighting == "none" ? awcc::Weighting::none : awcc::Weighting::duration;
  o.awcc.subsample = m.subsample == "parabolic" ? awcc::Subsample::parabolic : awcc::Subsample::none;
  o.awcc.path = m.path == "fft" ? awcc::CorrelationPath::fft : awcc::CorrelationPath::intervals;
  o.fscc.subsample = o.awcc.subsample;
  o.fscc.segments = m.segments;
  try {
    o.fscc.max_lag = awcc::parse_quantity(m.max_lag, awcc::Dimension::time);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("--max-lag: {}", e.what()));
  }
  if (auto why = o.awcc.validate(); !why.empty()) throw std::invalid_argument(why);
  if (auto why = o.fscc.validate(); !why.empty()) throw std::invalid_argument(why);
}

bool apply_method_options_or_log(const MethodCli& cli, StudyOptions& options) {
  try {
    apply_method_options(cli, options);
    return true;
  } catch (const std::invalid_argument& e) {
    spdlog::error("{}", e.what());
    return false;
  }
}

}  // namespace pdp
