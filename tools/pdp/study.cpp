#include "study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>

#include "awcc/phase_statistics.hpp"
#include "terminal.hpp"
#include "synth/synthesiser.hpp"

namespace pdp {

std::optional<double> Score::error() const {
  if (!value || !(truth != 0.0)) return std::nullopt;
  return *value / truth - 1.0;
}


namespace {

// Student t 0.975 quantile for df degrees of freedom.
double t975(std::int64_t df) {
  static const double table[] = {0, 12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                 2.201, 2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
                                 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
  if (df <= 0) return 0.0;
  if (df <= 30) return table[df];
  return 1.96 + 2.4 / static_cast<double>(df);  // within 0.002 of the exact quantile above 30
}

}  // namespace

Summary95 summarise95(const std::vector<double>& values) {
  Summary95 s;
  s.count = static_cast<std::int64_t>(values.size());
  if (values.empty()) return s;
  double sum = 0;
  for (double v : values) sum += v;
  s.mean = sum / static_cast<double>(values.size());
  if (values.size() < 2) {
    s.lower = s.upper = s.mean;
    return s;
  }
  double ss = 0;
  for (double v : values) ss += (v - s.mean) * (v - s.mean);
  const double sd = std::sqrt(ss / static_cast<double>(values.size() - 1));
  const double half = t975(s.count - 1) * sd / std::sqrt(static_cast<double>(values.size()));
  s.lower = s.mean - half;
  s.upper = s.mean + half;
  return s;
}

correction::Measurement awcc_measurement(const awcc::AwccResult& result, const awcc::PhaseStatistics& lead,
                                         double dx, double dy, int np, double fs, double duration) {
  correction::Measurement m;
  if (result.ok()) {
    m.velocity = result.velocity;
    m.turbulence_intensity = result.turbulence_intensity;
  }
  m.void_fraction = lead.void_fraction;
  m.bubble_count_rate = lead.bubble_count_rate;
  m.dx = dx;
  m.dy = dy;
  m.np = np;
  m.windows_accepted = result.windows_accepted;
  m.windows_total = result.windows_total;
  m.fs = fs;
  m.duration = duration;
  return m;
}

RunResult run_scene(const synth::Scene& scene, const StudyOptions& options) {
  // Processing correlates the first two tips: a study needs them (a one-tip
  // scene is fine for pdp synth, not here).
  if (scene.probe_tips().size() < 2) {
    throw std::invalid_argument(fmt::format("tips: the scene has {} tip; FSCC and AWCC need two (give tips or dx)",
                                            scene.probe_tips().size()));
  }
  RunResult r;
  r.scene = scene;
  synth::SynthesisOptions so;
  so.keep_velocity_history = options.window_truth && options.run_awcc;
  auto start = std::chrono::steady_clock::now();
  const auto syn = synth::synthesise(scene, so);
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
  const auto& lead = syn.signals[0];
  const auto& trail = syn.signals[1];
  r.dx = scene.streamwise_separation();
  r.dy = scene.lateral_separation();
  const double dx = r.dx;

  start = std::chrono::steady_clock::now();
  const auto phase = awcc::phase_statistics(lead);
  r.void_fraction = phase.void_fraction;
  r.count_rate = phase.bubble_count_rate;
  if (options.run_fscc) {
    const auto t = std::chrono::steady_clock::now();
    r.fscc = awcc::fscc(lead, trail, dx, options.fscc);
    r.seconds_fscc = seconds_since(t);
  }
  if (options.run_awcc) {
    const auto t = std::chrono::steady_clock::now();
    r.awcc = awcc::awcc(lead, trail, dx, options.awcc);
    r.seconds_awcc = seconds_since(t);
  }
  r.seconds_process = seconds_since(start);

  auto d32 = [&](double u) -> std::optional<double> {
    if (!(r.count_rate > 0.0)) return std::nullopt;
    return 1.5 * u * r.void_fraction / r.count_rate;
  };
  r.void_fraction_score = {r.void_fraction, r.truth_void_fraction};
  r.count_rate_score = {r.count_rate, r.truth_count_rate};
  r.fscc_velocity.truth = r.awcc_velocity.truth = r.truth_velocity;
  r.fscc_turbulence_intensity.truth = r.awcc_turbulence_intensity.truth = r.truth_turbulence_intensity;
  r.fscc_d32.truth = r.awcc_d32.truth = r.truth_d32;
  if (r.fscc && r.fscc->ok()) {
    r.fscc_velocity.value = r.fscc->velocity;
    r.fscc_turbulence_intensity.value = r.fscc->turbulence_intensity_chanson;
    r.fscc_d32.value = d32(r.fscc->velocity);
  }
  if (r.awcc && r.awcc->ok()) {
    r.awcc_velocity.value = r.awcc->velocity;
    r.awcc_turbulence_intensity.value = r.awcc->turbulence_intensity;
    r.awcc_d32.value = d32(r.awcc->velocity);
  }
  if (r.awcc && syn.history) {
    std::vector<double> diff, accepted, rejected;
    for (const auto& w : r.awcc->windows) {
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
  json out;
  out["seed"] = r.scene.seed;
  out["truth"] = {{"velocity", r.truth_velocity},
                  {"turbulence_intensity", r.truth_turbulence_intensity},
                  {"void_fraction", r.truth_void_fraction},
                  {"bubble_count_rate", r.truth_count_rate},
                  {"d32", r.truth_d32}};
  out["phase"] = {{"void_fraction", r.void_fraction}, {"bubble_count_rate", r.count_rate}};
  if (r.fscc) {
    out["fscc"] = {{"status", awcc::to_string(r.fscc->status)},
                   {"defined", r.fscc->ok()},
                   {"reason", r.fscc->ok() ? json(nullptr) : json(r.fscc->message)},
                   {"velocity", opt(r.fscc_velocity.value)},
                   {"turbulence_intensity_chanson", opt(r.fscc_turbulence_intensity.value)},
                   {"r12_max", r.fscc->r12_max},
                   {"d32", opt(r.fscc_d32.value)},
                   {"seconds", r.seconds_fscc}};
  }
  if (r.awcc) {
    out["awcc"] = {{"status", awcc::to_string(r.awcc->status)},
                   {"defined", r.awcc->ok()},
                   {"reason", r.awcc->ok() ? json(nullptr) : json(r.awcc->message)},
                   {"velocity", opt(r.awcc_velocity.value)},
                   {"turbulence_intensity", opt(r.awcc_turbulence_intensity.value)},
                   {"d32", opt(r.awcc_d32.value)},
                   {"windows_total", r.awcc->windows_total},
                   {"windows_accepted", r.awcc->windows_accepted},
                   {"seconds", r.seconds_awcc}};
  }
  out["error"] = {{"void_fraction", opt(r.void_fraction_score.error())},
                  {"bubble_count_rate", opt(r.count_rate_score.error())},
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

std::string run_report(const RunResult& r) {
  std::string out;
  auto val = [](const std::optional<double>& v, const char* f) {
    return v ? fmt::format(fmt::runtime(f), *v) : std::string("n/a");
  };
  auto err = [](const Score& s) {
    const auto e = s.error();
    return e ? fmt::format("{:+.2f} %", 100.0 * *e) : std::string("n/a");
  };
  out += fmt::format("{:<26}{:>12}{:>12}{:>10}{:>12}{:>10}\n", "quantity", "truth", "FSCC", "error", "AWCC", "error");
  out += fmt::format("{:<26}{:>12.4f}{:>12}{:>10}{:>12}{:>10}\n", "mean velocity (m/s)", r.truth_velocity,
                     val(r.fscc_velocity.value, "{:.4f}"), err(r.fscc_velocity), val(r.awcc_velocity.value, "{:.4f}"),
                     err(r.awcc_velocity));
  out += fmt::format("{:<26}{:>12.4f}{:>12}{:>10}{:>12}{:>10}\n", "turbulence intensity", r.truth_turbulence_intensity,
                     val(r.fscc_turbulence_intensity.value, "{:.4f}"), err(r.fscc_turbulence_intensity),
                     val(r.awcc_turbulence_intensity.value, "{:.4f}"), err(r.awcc_turbulence_intensity));
  out += fmt::format("{:<26}{:>12.3f}{:>12}{:>10}{:>12}{:>10}\n", "d32 (mm)", r.truth_d32 * 1e3,
                     val(r.fscc_d32.value ? std::optional(*r.fscc_d32.value * 1e3) : std::nullopt, "{:.3f}"),
                     err(r.fscc_d32), val(r.awcc_d32.value ? std::optional(*r.awcc_d32.value * 1e3) : std::nullopt, "{:.3f}"),
                     err(r.awcc_d32));
  out += fmt::format("{:<26}{:>12.5f}{:>12.5f}{:>10}   (phase statistics, both methods)\n", "void fraction",
                     r.truth_void_fraction, r.void_fraction, err(r.void_fraction_score));
  out += fmt::format("{:<26}{:>12.2f}{:>12.2f}{:>10}   (phase statistics, both methods)\n", "bubble count rate (1/s)",
                     r.truth_count_rate, r.count_rate, err(r.count_rate_score));
  out += "(FSCC turbulence intensity: Chanson's estimate)\n";
  if (r.fscc && !r.fscc->ok()) out += "FSCC undefined: " + r.fscc->message + "\n";
  if (r.awcc) {
    if (!r.awcc->ok()) out += "AWCC undefined: " + r.awcc->message + "\n";
    out += fmt::format("AWCC windows: {} accepted of {} ({} correlation, {} lag, {} outlier cutoff, {} constant)\n",
                       r.awcc->windows_accepted, r.awcc->windows_total, r.awcc->count(awcc::WindowFate::correlation),
                       r.awcc->count(awcc::WindowFate::lag), r.awcc->count(awcc::WindowFate::roc),
                       r.awcc->count(awcc::WindowFate::constant));
    if (r.window_bias) {
      out += fmt::format("window level: AWCC u_i minus window-averaged truth: bias {:+.4f} m/s, rms {:.4f} m/s\n",
                         *r.window_bias, *r.window_rms);
    }
    for (const auto& [label, s] : {std::pair{"accepted", &r.accepted_truth}, std::pair{"rejected", &r.rejected_truth}}) {
      out += fmt::format("true window velocity, {}: mean {:.4f}, sd {:.4f}, quartiles {:.4f} {:.4f} {:.4f} m/s ({})\n",
                         label, s->mean, s->std, s->percentiles[2], s->median, s->percentiles[4], s->count);
    }
  }
  out += fmt::format("run time: synthesis {:.3f} s, processing {:.3f} s (FSCC {:.3f} s, AWCC {:.3f} s)\n",
                     r.seconds_synth, r.seconds_process, r.seconds_fscc, r.seconds_awcc);
  return out;
}

}  // namespace pdp
