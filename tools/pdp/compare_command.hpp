#pragma once
// pdp compare: FSCC and AWCC side by side, on a recording or on a scene.

#include <CLI/CLI.hpp>
#include <string>

#include "command.hpp"
#include "scene_cli.hpp"

namespace pdp {

struct CompareOptions {
  std::string file;          ///< a recording; empty: synthesise the scene
  std::string dx = "0mm";    ///< for a recording
  std::string fs;            ///< for a recording without its rate
  SceneCli scene;
  OptionSet methods;
};

void setup_compare(CLI::App& app, Command& command, CompareOptions& options);
int run_compare(const CompareOptions& options);

}  // namespace pdp
