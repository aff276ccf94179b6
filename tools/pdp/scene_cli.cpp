#include "scene_cli.hpp"

#include <fmt/format.h>

#include "awcc/options.hpp"
#include "command.hpp"

namespace pdp {

void add_scene_options(CLI::App* cmd, SceneCli& cli) {
  const synth::Scene defaults;
  const auto fields = synth::scene_fields();
  cli.values.resize(fields.size());
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const auto& f = fields[i];
    auto* opt = cmd->add_option(flag_of(f.name), cli.values[i],
                                fmt::format("{} [default: {}]", f.help, f.format(defaults)));
    opt->group("Scene (units allowed, e.g. 5mm, 500kHz, 300s)");
    cli.options.push_back(opt);
  }
}

namespace {

// The scene fields given on the command line (over a config file), in declaration order.
std::vector<awcc::OptionSetting> given_scene_settings(const SceneCli& cli) {
  const auto fields = synth::scene_fields();
  std::vector<awcc::OptionSetting> settings;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (cli.options[i]->count() == 0) continue;
    settings.push_back({std::string(fields[i].name), cli.values[i], origin_of(fields[i].name)});
  }
  return settings;
}

}  // namespace

synth::Scene build_scene(const SceneCli& cli) {
  synth::Scene scene;
  const auto settings = given_scene_settings(cli);
  std::vector<bool> used(settings.size(), false);
  awcc::apply_settings(synth::scene_fields(), std::span<const awcc::OptionSetting>(settings), scene, used);
  if (const auto validation = scene.validate(); !validation.ok()) throw synth::invalid_scene(validation);
  return scene;
}

study::ProfileSpec build_profile(const std::string& path, const SceneCli& cli) {
  auto spec = study::load_profile_spec(path);
  const auto settings = given_scene_settings(cli);
  for (const auto& s : settings) {
    for (const auto law : {"void-fraction", "velocity", "tu", "bubble-diameter"}) {
      if (s.name == law) {
        throw awcc::OptionError(fmt::format("--{}: the profile's laws ({}) give each position's {}; change them in its "
                                            "[profile] table",
                                            s.name, path, s.name),
                                s.name);
      }
    }
  }
  std::vector<bool> used(settings.size(), false);
  awcc::apply_settings(synth::scene_fields(), std::span<const awcc::OptionSetting>(settings), spec.scene, used);
  spec.validate().throw_if_failed();
  return spec;
}

namespace {

// The study options among the libraries' declarations.
const std::vector<std::string_view> kStudyAwcc{"np", "filter-a", "roc", "weighting", "subsample", "path",
                                               "velocity-range"};

}  // namespace

void add_method_options(CLI::App* cmd, OptionSet& methods) {
  const study::RunOptions defaults;
  methods.add(cmd, awcc::awcc_option_fields(), defaults.awcc, "Methods", kStudyAwcc);
  methods.add(cmd, awcc::fscc_option_fields(), defaults.fscc, "Methods");
}

void apply_method_options(const OptionSet& methods, study::RunOptions& o) {
  awcc::method_options(methods.settings(), o.awcc, o.fscc);
}

}  // namespace pdp
