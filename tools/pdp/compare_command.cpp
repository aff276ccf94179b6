#include "compare_command.hpp"

#include <fmt/format.h>

#include "awcc/process.hpp"
#include "awcc/units.hpp"
#include "study/compare.hpp"

namespace pdp {

void setup_compare(CLI::App& app, Command& command, CompareOptions& o) {
  auto* cmd = app.add_subcommand("compare", "FSCC and AWCC side by side on a recording (or a synthesised scene)");
  command.app = cmd;
  add_config_option(command);
  path_option(cmd->add_option("file", o.file, "recording (without it, the scene given by the options is synthesised)"))
      ->check(CLI::ExistingFile);
  cmd->add_option("--rec-dx", o.dx, "recording: streamwise tip separation, m (units allowed)")->capture_default_str();
  cmd->add_option("--rec-fs", o.fs, "recording: sampling rate when the file lacks it, Hz");
  add_scene_options(cmd, o.scene);
  add_method_options(cmd, o.methods);
}

int run_compare(const CompareOptions& o) {
  study::RunOptions options;
  try {
    apply_method_options(o.methods, options);
    study::Comparison c;
    if (!o.file.empty()) {
      awcc::ProcessOptions reading;
      reading.dx = awcc::parse_quantity(o.dx, awcc::Dimension::length);
      if (!o.fs.empty()) reading.reader.fs = awcc::parse_quantity(o.fs, awcc::Dimension::frequency);
      if (!(reading.dx > 0.0)) {
        throw std::invalid_argument("--rec-dx: give the tip separation of the recording, e.g. --rec-dx 7.15mm");
      }
      c = study::compare_recording(o.file, reading, options);
    } else {
      c = study::compare_scene(build_scene(o.scene), options);
    }
    fmt::print("{}", study::comparison_report(c));
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
