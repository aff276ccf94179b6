#include "study/compare.hpp"

#include <chrono>
#include <fmt/format.h>

#include "study/clock.hpp"

namespace study {

Comparison compare(const awcc::BinarisedRecording& record, const RunOptions& options, double dx, double dy) {
  Comparison c;
  RunOptions fscc_alone = options, awcc_alone = options;
  fscc_alone.run_fscc = true;
  fscc_alone.run_awcc = false;
  awcc_alone.run_fscc = false;
  awcc_alone.run_awcc = true;
  auto start = std::chrono::steady_clock::now();
  c.fscc = *awcc::process_binarised(record, processing_options(fscc_alone, dx, dy)).fscc;
  c.fscc_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();
  c.awcc = *awcc::process_binarised(record, processing_options(awcc_alone, dx, dy)).awcc;
  c.awcc_seconds = seconds_since(start);
  return c;
}

Comparison compare_recording(const std::filesystem::path& file, const awcc::ProcessOptions& reading,
                             const RunOptions& options) {
  auto c = compare(awcc::binarise_recording(file, reading), options, reading.dx, reading.dy);
  c.what = file.string();
  return c;
}

Comparison compare_scene(const synth::Scene& scene, const RunOptions& options) {
  auto syn = synthesise_pair(scene);
  const double dx = scene.streamwise_separation(), dy = scene.lateral_separation();
  syn.signals.resize(2);
  auto c = compare(awcc::binary_recording(std::move(syn.signals), processing_options(options, dx, dy)), options, dx, dy);
  c.what = fmt::format("synthetic scene (seed {})", scene.seed);
  c.truth_velocity = syn.truth.realised.mean_velocity[0];
  c.truth_turbulence_intensity = syn.truth.realised.turbulence_intensity[0];
  return c;
}

std::string comparison_report(const Comparison& c) {
  const auto& f = c.fscc;
  const auto& a = c.awcc;
  auto num = [](bool ok, double v, const char* format) {
    return ok ? fmt::format(fmt::runtime(format), v) : std::string("n/a");
  };
  const auto& truth_u = c.truth_velocity;
  const auto& truth_tu = c.truth_turbulence_intensity;
  // Each method's status and AWCC's quality level (FSCC has none) before the values they qualify.
  std::string out = fmt::format("{}\n{}{}", c.what, fscc_status_line(f), awcc_status_line(a));
  out += fmt::format("{:<26}{:>14}{:>14}{}\n", "", "FSCC", "AWCC", truth_u ? fmt::format("{:>14}", "truth") : "");
  out += fmt::format("{:<26}{:>14}{:>14}{}\n", "velocity (m/s)", num(f.ok(), f.velocity, "{:.4f}"),
                     num(a.ok(), a.velocity, "{:.4f}"), truth_u ? fmt::format("{:>14.4f}", *truth_u) : "");
  out += fmt::format("{:<26}{:>14}{:>14}{}\n", "turbulence intensity",
                     num(f.turbulence_intensity_chanson.has_value(), f.turbulence_intensity_chanson.value_or(0), "{:.4f}"),
                     num(a.ok(), a.turbulence_intensity, "{:.4f}"), truth_tu ? fmt::format("{:>14.4f}", *truth_tu) : "");
  double mean_r12 = 0;
  std::int64_t kept = 0;
  for (const auto& w : a.windows) {
    if (w.fate != awcc::WindowFate::accepted) continue;
    mean_r12 += w.r12_max;
    ++kept;
  }
  out += fmt::format("{:<26}{:>14.4f}{:>14}\n", "R12max (AWCC: mean kept)", f.r12_max,
                     num(kept > 0, kept > 0 ? mean_r12 / static_cast<double>(kept) : 0.0, "{:.4f}"));
  out += fmt::format("{:<26}{:>14}{:>14}\n", "windows kept", "-", fmt::format("{} of {}", a.windows_accepted, a.windows_total));
  out += fmt::format("{:<26}{:>14.3f}{:>14.3f}\n", "run time (s)", c.fscc_seconds, c.awcc_seconds);
  return out;
}

}  // namespace study
