#include "compare_command.hpp"

#include <chrono>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "awcc/process.hpp"
#include "awcc/units.hpp"
#include "study.hpp"

namespace pdp {

void setup_compare(CLI::App& app, Command& command, CompareOptions& o) {
  auto* cmd = app.add_subcommand("compare", "FSCC and AWCC side by side on a recording (or a synthesised scene)");
  command.app = cmd;
  add_config_option(command);
  cmd->add_option("file", o.file, "recording (without it, the scene given by the options is synthesised)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--rec-dx", o.dx, "recording: streamwise tip separation, m (units allowed)")->capture_default_str();
  cmd->add_option("--rec-fs", o.fs, "recording: sampling rate when the file lacks it, Hz");
  add_scene_options(cmd, o.scene);
  add_method_options(cmd, o.methods);
}

int run_compare(const CompareOptions& o) {
  StudyOptions study;
  try {
    apply_method_options(o.methods, study);
    std::optional<awcc::FsccResult> f;
    std::optional<awcc::AwccResult> a;
    double tf = 0, ta = 0;
    std::optional<double> truth_u, truth_tu;
    std::string what;
    if (!o.file.empty()) {
      awcc::ProcessOptions p;
      p.dx = awcc::parse_quantity(o.dx, awcc::Dimension::length);
      if (!o.fs.empty()) p.reader.fs = awcc::parse_quantity(o.fs, awcc::Dimension::frequency);
      if (!(p.dx > 0.0)) {
        throw std::invalid_argument("--rec-dx: give the tip separation of the recording, e.g. --rec-dx 7.15mm");
      }
      const auto b = awcc::binarise_recording(o.file, p);
      auto t = std::chrono::steady_clock::now();
      f = awcc::fscc(b.leading, b.trailing, p.dx, study.fscc);
      tf = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
      t = std::chrono::steady_clock::now();
      a = awcc::awcc(b.leading, b.trailing, p.dx, study.awcc);
      ta = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
      what = o.file;
    } else {
      const auto scene = build_scene(o.scene);
      study.window_truth = false;
      const auto r = run_scene(scene, study);
      f = r.fscc;
      a = r.awcc;
      tf = r.seconds_fscc;
      ta = r.seconds_awcc;
      truth_u = r.truth_velocity;
      truth_tu = r.truth_turbulence_intensity;
      what = fmt::format("synthetic scene (seed {})", scene.seed);
    }
    auto num = [](bool ok, double v, const char* format) {
      return ok ? fmt::format(fmt::runtime(format), v) : std::string("n/a");
    };
    fmt::print("{}\n", what);
    fmt::print("{:<26}{:>14}{:>14}{}\n", "", "FSCC", "AWCC", truth_u ? fmt::format("{:>14}", "truth") : "");
    fmt::print("{:<26}{:>14}{:>14}{}\n", "velocity (m/s)", num(f->ok(), f->velocity, "{:.4f}"),
               num(a->ok(), a->velocity, "{:.4f}"), truth_u ? fmt::format("{:>14.4f}", *truth_u) : "");
    fmt::print("{:<26}{:>14}{:>14}{}\n", "turbulence intensity",
               num(f->turbulence_intensity_chanson.has_value(), f->turbulence_intensity_chanson.value_or(0), "{:.4f}"),
               num(a->ok(), a->turbulence_intensity, "{:.4f}"), truth_tu ? fmt::format("{:>14.4f}", *truth_tu) : "");
    double mean_r12 = 0;
    std::int64_t kept = 0;
    for (const auto& w : a->windows) {
      if (w.fate != awcc::WindowFate::accepted) continue;
      mean_r12 += w.r12_max;
      ++kept;
    }
    fmt::print("{:<26}{:>14.4f}{:>14}\n", "R12max (AWCC: mean kept)", f->r12_max,
               num(kept > 0, kept > 0 ? mean_r12 / static_cast<double>(kept) : 0.0, "{:.4f}"));
    fmt::print("{:<26}{:>14}{:>14}\n", "windows kept", "-", fmt::format("{} of {}", a->windows_accepted, a->windows_total));
    fmt::print("{:<26}{:>14.3f}{:>14.3f}\n", "run time (s)", tf, ta);
    if (!f->ok()) fmt::print("FSCC: {}\n", f->message);
    if (!a->ok()) fmt::print("AWCC: {}\n", a->message);
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
