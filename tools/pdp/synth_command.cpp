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
#include "study/profile.hpp"
#include "study/profile_run.hpp"
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
  path_option(cmd->add_option("--profile", options.profile,
                              "a synthetic profile (a TOML file with a [profile] table of the cross-section's laws and "
                              "a [scene] table; samples/stepped-profile.toml): one recording per position, "
                              "NAME-01.EXT ..., their positions in NAME.positions.csv (pdp process --manifest) and the "
                              "profile's truth in NAME.profile.json; scene options given override its [scene]"));

  add_scene_options(cmd, options.scene);
  options.synthesis.add(cmd, synth::synthesis_option_fields(), synth::SynthesisOptions{}, "Synthesis");
}

namespace {

// Writes the recording of one synthesis with its sidecar (and the bubble
// table when made), each under a temporary name; prints the truth unless quiet.
void write_synthesis(const std::filesystem::path& out, const synth::Scene& scene, const synth::Synthesis& synthesis,
                     synth::RecordingOptions recording) {
  if (synthesis.truth.reentries_missed > 0) {
    spdlog::warn("{} steps where the flow reversed beyond the bubble retirement allowance; some piercings may be "
                 "missing",
                 synthesis.truth.reentries_missed);
  }
  Progress progress("writing");
  recording.progress = [&progress](double f) { progress(f); };
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

// A synthetic profile: NAME-01.EXT ... (one recording per position), then
// NAME.positions.csv and NAME.profile.json, written last so that a profile
// whose manifest exists is whole.
int run_synth_profile(const SynthOptions& options, const synth::SynthesisOptions& so,
                      const synth::RecordingOptions& recording) {
  study::ProfileSpec spec;
  try {
    spec = build_profile(options.profile, options.scene);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  const std::filesystem::path out = options.output;
  const auto stem = out.parent_path() / out.stem();
  const auto extension = out.extension().string();
  std::vector<std::string> names;
  try {
    for (std::size_t i = 0; i < spec.positions.size(); ++i) {
      const auto scene = study::position_scene(spec, i);
      if (const auto why = synth::check_recordable(scene, scene.probe_tips().size(), recording.format); !why.empty()) {
        throw awcc::OptionError(fmt::format("{}: position {}: {}", options.output, i + 1, why));
      }
      const std::filesystem::path file = fmt::format("{}-{:02}{}", stem.string(), i + 1, extension);
      synth::Synthesis synthesis;
      {
        Progress progress(fmt::format("position {}/{}", i + 1, spec.positions.size()));
        auto position_options = so;
        position_options.progress = [&progress](double f) { progress(f); };
        synthesis = synth::synthesise(scene, position_options);
      }
      write_synthesis(file, scene, synthesis, recording);
      names.push_back(file.filename().string());
      if (!options.quiet) {
        fmt::print("position {} (y = {}): c {:.4f} (law {:.4f}), u {:.4f} m/s (law {:.4f}), {} chords at the first tip\n",
                   i + 1, awcc::format_quantity(spec.positions[i], awcc::Dimension::length),
                   synthesis.truth.tips[0].void_fraction, scene.void_fraction,
                   synthesis.truth.realised.mean_velocity[0], scene.velocity, synthesis.truth.tips[0].chords);
      }
    }
    const auto truth = study::profile_truth(spec, awcc::ProfileFlowOptions{}.levels);
    awcc::write_text_atomically(stem.string() + ".positions.csv", study::manifest_text(names, spec.positions));
    awcc::write_text_atomically(stem.string() + ".profile.json", awcc::json_text(study::profile_truth_json(spec, truth)));
    spdlog::info("wrote {} recordings, {}.positions.csv and {}.profile.json", spec.positions.size(), stem.string(),
                 stem.string());
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace

int run_synth(const SynthOptions& options) {
  synth::Scene scene;
  synth::SynthesisOptions so;
  try {
    if (options.profile.empty()) scene = build_scene(options.scene);
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
  if (!options.profile.empty()) return run_synth_profile(options, so, recording);
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
    const auto write_start = std::chrono::steady_clock::now();
    write_synthesis(options.output, scene, synthesis, recording);
    spdlog::info("synthesis {:.2f} s, file {:.2f} s, peak memory {:.0f} MB", t_synth, study::seconds_since(write_start),
                 peak_memory_mb());
    if (!options.quiet) fmt::print("{}", synthesis.truth.report());
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
