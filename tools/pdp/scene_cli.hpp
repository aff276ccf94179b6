#pragma once
// The options shared by pdp synth, validate, compare, sweep and bench: every
// scene field as --name (units allowed), and the AWCC and FSCC options of the
// studies, both registered from the libraries' declarations.

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cli_options.hpp"
#include "study/profile.hpp"
#include "study/run.hpp"
#include "synth/scene.hpp"

namespace pdp {

struct SceneCli {
  std::vector<std::string> values;       ///< one per scene field, as typed
  std::vector<CLI::Option*> options;
};

/// Adds one option per scene field to `cmd`.
void add_scene_options(CLI::App* cmd, SceneCli& cli);

/// Defaults, then the given fields (command line over config file);
/// validated. Throws std::invalid_argument naming the option, the field and
/// the allowed range.
synth::Scene build_scene(const SceneCli& cli);

/// The synthetic profile of `path` (study/profile.hpp), its base scene's
/// fields overridden by those given on the command line (the laws' fields
/// refused there); validated. Throws InputError for the file, OptionError
/// naming the option or field.
study::ProfileSpec build_profile(const std::string& path, const SceneCli& cli);

/// The AWCC and FSCC options of the studies (validate, compare, sweep, bench).
void add_method_options(CLI::App* cmd, OptionSet& methods);
/// Applies them; throws std::invalid_argument naming the option.
void apply_method_options(const OptionSet& methods, study::RunOptions& options);

}  // namespace pdp
