#pragma once
// pdp synth: synthesise a scene into a recording and its truth sidecar.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli_options.hpp"
#include "command.hpp"
#include "scene_cli.hpp"

namespace pdp {

struct SynthOptions {
  SceneCli scene;                        ///< scene fields
  OptionSet synthesis;                   ///< synth::synthesis_option_fields() (bubble-truth)
  std::string output;                    ///< recording path (.flac, .wav, .w64, .rf64)
  std::string signal = "binary";         ///< binary | voltage
  std::string format;                    ///< flac | wav | w64 | rf64; default from the extension
  double flac_compression = 0.0;         ///< 0 (fastest) to 1 (smallest)
  bool quiet = false;                    ///< no truth summary on stdout
  std::string profile;                   ///< a synthetic profile's file (study/profile.hpp): a recording per position
};

void setup_synth(CLI::App& app, Command& command, SynthOptions& options);
int run_synth(const SynthOptions& options);

}  // namespace pdp
