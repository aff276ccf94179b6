#pragma once
// The scene options shared by pdp synth, validate, compare and bench: every
// scene field as --name (units allowed) and --config scene.toml, with the
// command line overriding the file.

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "synth/scene.hpp"

namespace pdp {

struct SceneCli {
  std::string config;
  std::vector<std::string> values;       ///< one per scene field, as typed
  std::vector<CLI::Option*> options;
};

/// Adds --config and one option per scene field to `cmd`.
void add_scene_options(CLI::App* cmd, SceneCli& cli);

/// Defaults, then the TOML file, then the command line; validated. Logs the
/// problems (naming the file or option, the field and the range) and returns
/// empty on any.
std::optional<synth::Scene> build_scene(const SceneCli& cli);

/// The AWCC and FSCC options shared by validate, compare, sweep and bench.
struct MethodCli {
  int np = 10;
  double filter_a = 0.4;
  std::string roc = "on";
  std::string weighting = "duration";
  std::string subsample = "none";
  std::string path = "intervals";
  std::string max_lag = "20ms";
  int segments = 1;
};
void add_method_options(CLI::App* cmd, MethodCli& cli);
struct StudyOptions;
/// Throws std::invalid_argument naming the option.
void apply_method_options(const MethodCli& cli, StudyOptions& options);
/// The same, logging the problem and returning false instead of throwing
/// (as build_scene does for the scene).
bool apply_method_options_or_log(const MethodCli& cli, StudyOptions& options);

}  // namespace pdp
