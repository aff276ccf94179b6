#include "synth_command.hpp"

#include <chrono>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "awcc/atomic_output.hpp"
#include "awcc/json_text.hpp"
#include "study/clock.hpp"
#include "synth/recording.hpp"
#include "synth/sidecar.hpp"
#include "synth/synthesiser.hpp"
#include "terminal.hpp"

namespace pdp {

void setup_synth(CLI::App& app, Command& command, SynthOptions& options) {
  auto* cmd = app.add_subcommand("synth", "Synthesise a scene: write a recording and its <name>.truth.json sidecar");
  command.app = cmd;
  add_config_option(command);
  command.required.push_back(path_option(
      cmd->add_option("-o,--output", options.output,
                      "recording to write (.flac, .wav, .w64, .rf64; .h5 or .hdf5: pdp-sim's layout, datasets "
                      "'signal' (samples x tips, uint8 0/1, or int16 counts with 'volts_per_count' for --signal "
                      "voltage, which pdp-sim itself does not write) and 'time')")));
  cmd->add_option("--signal", options.signal, "binary (0 water, 1 air) or voltage (raw int16 counts)")
      ->check(CLI::IsMember({"binary", "voltage"}))
      ->capture_default_str();
  cmd->add_option("--format", options.format, "flac | wav | w64 | rf64 | h5 [default: from the extension]")
      ->check(CLI::IsMember({"flac", "wav", "w64", "rf64", "h5"}));
  cmd->add_option("--flac-compression", options.flac_compression, "FLAC compression level, 0 fastest to 1 smallest")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", options.quiet, "do not print the truth summary");

  add_scene_options(cmd, options.scene);
  options.synthesis.add(cmd, synth::synthesis_option_fields(), synth::SynthesisOptions{}, "Synthesis");
}

int run_synth(const SynthOptions& options) {
  synth::Scene scene;
  synth::SynthesisOptions so;
  try {
    scene = build_scene(options.scene);
    const auto given = options.synthesis.settings();
    std::vector<bool> used(given.size(), false);
    awcc::apply_settings(synth::synthesis_option_fields(), std::span<const awcc::OptionSetting>(given), so, used);
  } catch (const std::exception& e) {
    return report_error(e);
  }

  synth::RecordingOptions recording;
  recording.signal = options.signal == "voltage" ? synth::SignalKind::voltage : synth::SignalKind::binary;
  recording.flac_compression = options.flac_compression;
  if (!options.format.empty()) {
    recording.format = *synth::format_from_extension("x." + options.format);
  } else if (auto f = synth::format_from_extension(options.output)) {
    recording.format = *f;
  } else {
    spdlog::error("{}: unknown recording extension; use .flac, .wav, .w64, .rf64 or .h5, or give --format",
                  options.output);
    return exit_bad_usage;
  }
  if (const auto why = synth::check_recordable(scene, scene.probe_tips().size(), recording.format); !why.empty()) {
    spdlog::error("{}: {}", options.output, why);
    return exit_bad_usage;
  }

  try {
    const auto start = std::chrono::steady_clock::now();
    synth::Synthesis synthesis;
    {
      Progress progress("synthesising");
      so.progress = [&progress](double f) { progress(f); };
      synthesis = synth::synthesise(scene, so);
    }
    const double t_synth = study::seconds_since(start);
    if (synthesis.truth.reentries_missed > 0) {
      spdlog::warn("{} steps where the flow reversed beyond the bubble retirement allowance; some piercings may be "
                   "missing",
                   synthesis.truth.reentries_missed);
    }
    const auto write_start = std::chrono::steady_clock::now();
    {
      Progress progress("writing");
      recording.progress = [&progress](double f) { progress(f); };
      const std::filesystem::path out = options.output;
      const auto sidecar = synth::sidecar_path(out);
      const synth::BubbleTruth* bubbles = synthesis.bubbles ? &*synthesis.bubbles : nullptr;
      awcc::write_atomically(out, [&](const std::filesystem::path& temporary) {
        synth::write_recording(temporary, scene, synthesis.signals, recording);
        if (bubbles) synth::write_bubble_truth_csv(synth::bubble_truth_path(out), *bubbles);
        try {
          awcc::write_text_atomically(sidecar,
                                      awcc::json_text(synth::sidecar_json(synthesis.truth, recording, out, bubbles)));
        } catch (...) {
          // No table without its sidecar and recording.
          if (bubbles) std::filesystem::remove(synth::bubble_truth_path(out));
          throw;
        }
      });
      if (bubbles) {
        spdlog::info("wrote {}, {} and {} ({} bubbles)", out.string(), sidecar.string(),
                     synth::bubble_truth_path(out).string(), bubbles->size());
      } else {
        spdlog::info("wrote {} and {}", out.string(), sidecar.string());
      }
    }
    spdlog::info("synthesis {:.2f} s, file {:.2f} s, peak memory {:.0f} MB", t_synth, study::seconds_since(write_start),
                 peak_memory_mb());
    if (!options.quiet) fmt::print("{}", synthesis.truth.report());
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
