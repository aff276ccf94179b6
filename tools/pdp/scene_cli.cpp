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
    auto* opt = cmd->add_option(fmt::format("--{}", f.name), cli.values[i],
                                fmt::format("{} [default: {}]", f.help, f.format(defaults)));
    opt->group("Scene (units allowed, e.g. 5mm, 500kHz, 300s)");
    cli.options.push_back(opt);
  }
}

synth::Scene build_scene(const SceneCli& cli) {
  synth::Scene scene;
  const auto fields = synth::scene_fields();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (cli.options[i]->count() == 0) continue;
    try {
      fields[i].parse(scene, cli.values[i]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("{}--{}: {}", origin_of(fields[i].name), fields[i].name, e.what()));
    }
  }
  if (const auto errors = scene.validate(); !errors.empty()) {
    std::string all;
    for (const auto& e : errors) all += "\n  " + e;
    throw std::invalid_argument("invalid scene:" + all);
  }
  return scene;
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
  methods.apply(awcc::awcc_option_fields(), o.awcc);
  methods.apply(awcc::fscc_option_fields(), o.fscc);
  o.fscc.subsample = o.awcc.subsample;  // FSCC refines its peak as AWCC does
  if (auto why = o.awcc.validate(); !why.empty()) throw std::invalid_argument(why);
  if (auto why = o.fscc.validate(); !why.empty()) throw std::invalid_argument(why);
}

}  // namespace pdp
