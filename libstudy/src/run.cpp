#include "study/run.hpp"

#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

#include "awcc/random.hpp"
#include "study/clock.hpp"

namespace study {

std::optional<double> Score::error() const {
  if (!value || !(truth != 0.0)) return std::nullopt;
  return *value / truth - 1.0;
}

awcc::ProcessOptions processing_options(const RunOptions& options, double dx, double dy) {
  awcc::ProcessOptions p;
  p.dx = dx;
  p.dy = dy;
  p.fscc = options.run_fscc;
  p.awcc = options.run_awcc;
  p.fscc_options = options.fscc;
  p.awcc_options = options.awcc;
  p.structure.enabled = false;
  p.velocity_spectrum = false;
  p.sizes = false;
  p.parallel_fscc = false;  // a study's rows fill the cores, one row a thread
  return p;
}

awcc::ProcessResult process_synthesis(awcc::AirIntervals leading, awcc::AirIntervals trailing,
                                      const awcc::ProcessOptions& options) {
  if (options.awcc_options.signal != awcc::CorrelationSignal::binary) {
    throw std::invalid_argument(
        "signal = raw: a synthesised record in memory holds binary signals only; write it as a voltage recording "
        "(synth::write_recording) and process the file");
  }
  std::vector<awcc::AirIntervals> signals;
  signals.push_back(std::move(leading));
  signals.push_back(std::move(trailing));
  return awcc::process_binarised(awcc::binary_recording(std::move(signals), options), options);
}

synth::Synthesis synthesise_pair(const synth::Scene& scene, const synth::SynthesisOptions& options) {
  // Processing correlates the first two tips: a study needs them (a one-tip
  // scene is fine for pdp synth, not here).
  if (scene.probe_tips().size() < 2) {
    throw std::invalid_argument(fmt::format("tips: the scene has {} tip; FSCC and AWCC need two (give tips or dx)",
                                            scene.probe_tips().size()));
  }
  return synth::synthesise(scene, options);
}

RunResult run_scene(const synth::Scene& scene, const RunOptions& options) {
  RunResult r;
  r.scene = scene;
  synth::SynthesisOptions so;
  so.keep_velocity_history = options.window_truth && options.run_awcc;
  auto start = std::chrono::steady_clock::now();
  auto syn = synthesise_pair(scene, so);
  r.seconds_synth = seconds_since(start);
  const auto& truth = syn.truth;
  r.truth_velocity = truth.realised.mean_velocity[0];
  r.truth_turbulence_intensity = truth.realised.turbulence_intensity[0];
  r.truth_void_fraction = truth.tips[0].void_fraction;
  r.truth_count_rate = static_cast<double>(truth.tips[0].bubbles_pierced) / scene.duration;
  {
    // d32 of the bubble population: E[d^3] / E[d^2] (d_b for equal sizes).
    const double s = scene.diameter_log_sd;
    r.truth_d32 = scene.bubble_diameter * std::exp(2.5 * s * s);
    if (s == 0.0) r.truth_d32 = scene.bubble_diameter;
  }
  r.dx = scene.streamwise_separation();
  r.dy = scene.lateral_separation();

  start = std::chrono::steady_clock::now();
  const auto processing = processing_options(options, r.dx, r.dy);
  const auto tips = scene.probe_tips();
  if (tips.size() >= 4) {
    // Every tip, as pdp process reads a recording that states its tips.
    if (processing.awcc_options.signal != awcc::CorrelationSignal::binary) {
      throw std::invalid_argument("signal = raw: a synthesised record in memory holds binary signals only");
    }
    std::vector<awcc::Vec3> positions;
    for (const auto& t : tips) positions.push_back({t.x, t.y, t.z});
    r.processed =
        awcc::process_binarised(awcc::binary_recording(std::move(syn.signals), processing, {}, positions), processing);
  } else {
    r.processed = process_synthesis(std::move(syn.signals[0]), std::move(syn.signals[1]), processing);
  }
  r.seconds_process = seconds_since(start);
  for (std::size_t i = 0; i < 3; ++i) {
    r.multi_tip_velocity[i].truth = truth.realised.mean_velocity[i];
    r.multi_tip_turbulence_intensity[i].truth = truth.realised.turbulence_intensity[i];
  }
  r.multi_tip_interfacial_area.truth = truth.expected_interfacial_area;
  if (r.processed.probe && r.processed.probe->vectors.ok()) {
    const auto& v = r.processed.probe->vectors;
    for (std::size_t i = 0; i < 3; ++i) {
      r.multi_tip_velocity[i].value = v.velocity[i];
      r.multi_tip_turbulence_intensity[i].value = v.turbulence_intensity[i];
    }
    r.multi_tip_interfacial_area.value = v.interfacial_area;
  }
  r.measurement = correction::measurement_of(r.processed);

  const auto& p = r.processed;
  const auto& lead = p.tips.at(0).phase;
  r.void_fraction = {lead.void_fraction, r.truth_void_fraction};
  r.count_rate = {lead.bubble_count_rate, r.truth_count_rate};
  r.fscc_velocity.truth = r.awcc_velocity.truth = r.truth_velocity;
  r.fscc_turbulence_intensity.truth = r.awcc_turbulence_intensity.truth = r.truth_turbulence_intensity;
  r.fscc_d32.truth = r.awcc_d32.truth = r.truth_d32;
  if (p.fscc && p.fscc->ok()) {
    r.fscc_velocity.value = p.fscc->velocity;
    r.fscc_turbulence_intensity.value = p.fscc->turbulence_intensity_chanson;
  }
  if (p.awcc && p.awcc->ok()) {
    r.awcc_velocity.value = p.awcc->velocity;
    r.awcc_turbulence_intensity.value = p.awcc->turbulence_intensity;
  }
  const auto source = p.velocity_source();
  if (source == awcc::VelocitySource::fscc) r.fscc_d32.value = lead.sauter_diameter;
  if (source == awcc::VelocitySource::awcc) r.awcc_d32.value = lead.sauter_diameter;
  if (p.awcc && syn.history) {
    std::vector<double> diff, accepted, rejected;
    for (const auto& w : p.awcc->windows) {
      const double t = syn.history->mean_velocity(w.start_time, w.start_time + w.duration);
      if (w.fate == awcc::WindowFate::accepted) {
        diff.push_back(w.velocity - t);
        accepted.push_back(t);
      } else {
        rejected.push_back(t);
      }
    }
    if (!diff.empty()) {
      double sum = 0, ss = 0;
      for (double d : diff) {
        sum += d;
        ss += d * d;
      }
      r.window_bias = sum / static_cast<double>(diff.size());
      r.window_rms = std::sqrt(ss / static_cast<double>(diff.size()));
    }
    r.accepted_truth = awcc::summarise(std::move(accepted));
    r.rejected_truth = awcc::summarise(std::move(rejected));
  }
  return r;
}

namespace {

using nlohmann::json;

json opt(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

// Summary::percentiles holds the 5, 10, 25, 50, 75, 90 and 95th.
json spread_json(const awcc::Summary& s) {
  return json{{"count", s.count},           {"mean", s.mean},   {"sd", s.std},
              {"q25", s.percentiles[2]},    {"median", s.median}, {"q75", s.percentiles[4]}};
}

}  // namespace

json run_to_json(const RunResult& r) {
  const auto& p = r.processed;
  json out;
  out["seed"] = r.scene.seed;
  out["generator_version"] = awcc::generator_version;
  out["truth"] = {{"velocity", r.truth_velocity},
                  {"turbulence_intensity", r.truth_turbulence_intensity},
                  {"void_fraction", r.truth_void_fraction},
                  {"bubble_count_rate", r.truth_count_rate},
                  {"d32", r.truth_d32}};
  out["phase"] = {{"void_fraction", opt(r.void_fraction.value)}, {"bubble_count_rate", opt(r.count_rate.value)}};
  if (p.fscc) {
    out["fscc"] = {{"status", awcc::to_string(p.fscc->status)},
                   {"reason", p.fscc->ok() ? json(nullptr) : json(p.fscc->message)},
                   {"velocity", opt(r.fscc_velocity.value)},
                   {"turbulence_intensity_chanson", opt(r.fscc_turbulence_intensity.value)},
                   {"r12_max", p.fscc->r12_max},
                   {"d32", opt(r.fscc_d32.value)}};
  }
  if (p.awcc) {
    out["awcc"] = {
        {"status", awcc::to_string(p.awcc->status)},
        {"reason", p.awcc->ok() ? json(nullptr) : json(p.awcc->message)},
        {"quality", awcc::to_string(p.awcc->quality)},
        {"quality_reason", p.awcc->quality == awcc::AwccQuality::ok ? json(nullptr) : json(p.awcc->quality_reason)},
        {"velocity", opt(r.awcc_velocity.value)},
        {"turbulence_intensity", opt(r.awcc_turbulence_intensity.value)},
        {"d32", opt(r.awcc_d32.value)},
        {"windows_total", p.awcc->windows_total},
        {"windows_accepted", p.awcc->windows_accepted}};
  }
  out["error"] = {{"void_fraction", opt(r.void_fraction.error())},
                  {"bubble_count_rate", opt(r.count_rate.error())},
                  {"fscc", {{"velocity", opt(r.fscc_velocity.error())},
                            {"turbulence_intensity", opt(r.fscc_turbulence_intensity.error())},
                            {"d32", opt(r.fscc_d32.error())}}},
                  {"awcc", {{"velocity", opt(r.awcc_velocity.error())},
                            {"turbulence_intensity", opt(r.awcc_turbulence_intensity.error())},
                            {"d32", opt(r.awcc_d32.error())}}}};
  out["windows"] = {{"bias", opt(r.window_bias)},
                    {"rms", opt(r.window_rms)},
                    {"accepted_true_velocity", spread_json(r.accepted_truth)},
                    {"rejected_true_velocity", spread_json(r.rejected_truth)}};
  out["seconds_synth"] = r.seconds_synth;
  out["seconds_process"] = r.seconds_process;
  return out;
}

std::string fscc_status_line(const awcc::FsccResult& f) {
  return f.ok() ? std::string("FSCC: status ok\n")
                : fmt::format("FSCC: status {}, no velocity: {}\n", awcc::to_string(f.status), f.message);
}

std::string awcc_status_line(const awcc::AwccResult& a) {
  // Insufficient whenever not ok: the quality reason is the status message, said once.
  if (!a.ok()) {
    return fmt::format("AWCC: status {}, quality insufficient, no velocity: {}\n", awcc::to_string(a.status),
                       a.message);
  }
  if (a.quality == awcc::AwccQuality::low) {
    return fmt::format("AWCC: status ok, quality low (its values are flagged): {}\n", a.quality_reason);
  }
  return "AWCC: status ok, quality ok\n";
}

std::string run_report(const RunResult& r) {
  const auto& p = r.processed;
  std::string out;
  auto val = [](const std::optional<double>& v, const char* f) {
    return v ? fmt::format(fmt::runtime(f), *v) : std::string("n/a");
  };
  auto err = [](const Score& s) {
    const auto e = s.error();
    return e ? fmt::format("{:+.2f} %", 100.0 * *e) : std::string("n/a");
  };
  auto mm = [](const std::optional<double>& v) { return v ? std::optional(*v * 1e3) : std::nullopt; };
  // Each method's status and AWCC's quality level (FSCC has none) before the values they qualify.
  if (p.fscc) out += fscc_status_line(*p.fscc);
  if (p.awcc) out += awcc_status_line(*p.awcc);
  out += fmt::format("{:<26}{:>12}{:>12}{:>10}{:>12}{:>10}\n", "quantity", "truth", "FSCC", "error", "AWCC", "error");
  out += fmt::format("{:<26}{:>12.4f}{:>12}{:>10}{:>12}{:>10}\n", "mean velocity (m/s)", r.truth_velocity,
                     val(r.fscc_velocity.value, "{:.4f}"), err(r.fscc_velocity), val(r.awcc_velocity.value, "{:.4f}"),
                     err(r.awcc_velocity));
  out += fmt::format("{:<26}{:>12.4f}{:>12}{:>10}{:>12}{:>10}\n", "turbulence intensity", r.truth_turbulence_intensity,
                     val(r.fscc_turbulence_intensity.value, "{:.4f}"), err(r.fscc_turbulence_intensity),
                     val(r.awcc_turbulence_intensity.value, "{:.4f}"), err(r.awcc_turbulence_intensity));
  out += fmt::format("{:<26}{:>12.3f}{:>12}{:>10}{:>12}{:>10}\n", "d32 (mm)", r.truth_d32 * 1e3,
                     val(mm(r.fscc_d32.value), "{:.3f}"), err(r.fscc_d32), val(mm(r.awcc_d32.value), "{:.3f}"),
                     err(r.awcc_d32));
  out += fmt::format("{:<26}{:>12.5f}{:>12}{:>10}   (phase statistics, both methods)\n", "void fraction",
                     r.truth_void_fraction, val(r.void_fraction.value, "{:.5f}"), err(r.void_fraction));
  out += fmt::format("{:<26}{:>12.2f}{:>12}{:>10}   (phase statistics, both methods)\n", "bubble count rate (1/s)",
                     r.truth_count_rate, val(r.count_rate.value, "{:.2f}"), err(r.count_rate));
  out += "(FSCC turbulence intensity: Chanson's estimate; d32 from the velocity pdp process chooses: AWCC's of "
         "quality ok, else FSCC's)\n";
  if (p.awcc) {
    const auto& a = *p.awcc;
    out += fmt::format("AWCC windows: {} accepted of {} ({} correlation, {} lag, {} outlier cutoff, {} constant)\n",
                       a.windows_accepted, a.windows_total, a.count(awcc::WindowFate::correlation),
                       a.count(awcc::WindowFate::lag), a.count(awcc::WindowFate::roc),
                       a.count(awcc::WindowFate::constant));
    if (r.window_bias) {
      out += fmt::format(
          "window level (AWCC quality {}): AWCC u_i minus window-averaged truth: bias {:+.4f} m/s, rms "
          "{:.4f} m/s\n",
          awcc::to_string(a.quality), *r.window_bias, *r.window_rms);
    }
    for (const auto& [label, s] : {std::pair{"accepted", &r.accepted_truth}, std::pair{"rejected", &r.rejected_truth}}) {
      out += fmt::format("true window velocity, {}: mean {:.4f}, sd {:.4f}, quartiles {:.4f} {:.4f} {:.4f} m/s ({})\n",
                         label, s->mean, s->std, s->percentiles[2], s->median, s->percentiles[4], s->count);
    }
  }
  out += fmt::format("run time: synthesis {:.3f} s, processing {:.3f} s (phase statistics, FSCC and AWCC, as pdp process)\n",
                     r.seconds_synth, r.seconds_process);
  return out;
}

}  // namespace study
