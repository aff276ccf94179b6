#include "study/validate.hpp"

#include <cmath>
#include <fmt/format.h>

#include "awcc/random.hpp"

namespace study {

using nlohmann::json;

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

std::vector<RunResult> run_repeats(const synth::Scene& scene, const RunOptions& options, int repeat,
                                   const Progress& progress) {
  std::vector<RunResult> runs;
  for (int i = 0; i < repeat; ++i) {
    synth::Scene s = scene;
    if (repeat > 1) s.seed = awcc::derive_seed(scene.seed, static_cast<std::uint64_t>(i));
    runs.push_back(run_scene(s, options));
    if (progress) progress(static_cast<double>(i + 1) / repeat);
  }
  return runs;
}

RepeatSummary summarise_runs(const std::vector<RunResult>& runs) {
  struct Series {
    const char* name;
    const char* key;
    bool absolute;
    std::optional<double> (*error)(const RunResult&);
  };
  static const Series series[] = {
      {"fscc velocity", "fscc_velocity", false, [](const RunResult& r) { return r.fscc_velocity.error(); }},
      {"fscc turbulence intensity", "fscc_turbulence_intensity", false,
       [](const RunResult& r) { return r.fscc_turbulence_intensity.error(); }},
      {"fscc d32", "fscc_d32", false, [](const RunResult& r) { return r.fscc_d32.error(); }},
      {"awcc velocity", "awcc_velocity", false, [](const RunResult& r) { return r.awcc_velocity.error(); }},
      {"awcc turbulence intensity", "awcc_turbulence_intensity", false,
       [](const RunResult& r) { return r.awcc_turbulence_intensity.error(); }},
      {"awcc d32", "awcc_d32", false, [](const RunResult& r) { return r.awcc_d32.error(); }},
      {"void fraction", "void_fraction", false, [](const RunResult& r) { return r.void_fraction.error(); }},
      {"bubble count rate", "bubble_count_rate", false, [](const RunResult& r) { return r.count_rate.error(); }},
      // AWCC's windows, over the runs AWCC gives a velocity (quality ok or low), as its other errors.
      {"window bias (m/s)", "window_bias", true,
       [](const RunResult& r) { return r.awcc_velocity.value ? r.window_bias : std::nullopt; }},
      {"window rms (m/s)", "window_rms", true,
       [](const RunResult& r) { return r.awcc_velocity.value ? r.window_rms : std::nullopt; }},
  };
  RepeatSummary out;
  for (const auto& s : series) {
    std::vector<double> values;
    for (const auto& r : runs)
      if (const auto e = s.error(r)) values.push_back(*e);
    out.errors.push_back({s.name, s.key, s.absolute, summarise95(values)});
  }
  for (const auto& r : runs) {
    out.fscc_undefined += !r.fscc_velocity.value;
    out.awcc_undefined += !r.awcc_velocity.value;
    if (!r.processed.awcc) continue;
    switch (r.processed.awcc->quality) {
      case awcc::AwccQuality::ok:
        ++out.awcc_ok;
        break;
      case awcc::AwccQuality::low:
        ++out.awcc_low;
        break;
      case awcc::AwccQuality::insufficient:
        ++out.awcc_insufficient;
        break;
    }
  }
  return out;
}

nlohmann::json repeats_to_json(const std::vector<RunResult>& runs, const RepeatSummary& summary) {
  nlohmann::json j;
  nlohmann::json errors = nlohmann::json::object();
  for (const auto& e : summary.errors) {
    const auto& m = e.summary;
    // No run gave the value: no mean and no interval (not zeros).
    errors[e.key] = {{"runs", m.count},
                     {"mean", m.count ? json(m.mean) : json(nullptr)},
                     {"ci95", m.count ? json{m.lower, m.upper} : json(nullptr)}};
  }
  j["repeat"] = runs.size();
  j["error"] = errors;
  j["awcc_quality"] = {{"ok", summary.awcc_ok}, {"low", summary.awcc_low}, {"insufficient", summary.awcc_insufficient}};
  j["runs"] = nlohmann::json::array();
  for (const auto& r : runs) j["runs"].push_back(run_to_json(r));
  if (!runs.empty()) {
    j["truth"] = j["runs"][0]["truth"];
    j["fscc"] = j["runs"][0].value("fscc", nlohmann::json());
    j["awcc"] = j["runs"][0].value("awcc", nlohmann::json());
  }
  return j;
}

std::string repeats_report(const std::vector<RunResult>& runs, const RepeatSummary& summary, std::uint64_t seed) {
  std::string out = fmt::format("{} runs of the scene (seeds derived from {}); relative errors (value / truth - 1):\n",
                                runs.size(), seed);
  out += fmt::format("{:<28}{:>8}{:>12}{:>24}\n", "error", "runs", "mean", "95 % interval");
  for (const auto& e : summary.errors) {
    const auto& m = e.summary;
    const double scale = e.absolute ? 1.0 : 100.0;
    const char* unit = e.absolute ? "" : " %";
    if (m.count == 0) {
      out += fmt::format("{:<28}{:>8}{:>12}{:>24}\n", e.name, m.count, "n/a", "n/a");
      continue;
    }
    out += fmt::format("{:<28}{:>8}{:>10.3f}{}{:>14.3f}{} to {:.3f}{}\n", e.name, m.count, m.mean * scale, unit,
                       m.lower * scale, unit, m.upper * scale, unit);
  }
  out += fmt::format(
      "AWCC quality: {} runs ok, {} low, {} insufficient (no velocity); the AWCC errors are over the ok "
      "and low runs\n",
      summary.awcc_ok, summary.awcc_low, summary.awcc_insufficient);
  if (summary.fscc_undefined || summary.awcc_undefined) {
    out += fmt::format("velocity undefined in {} FSCC and {} AWCC runs\n", summary.fscc_undefined,
                       summary.awcc_undefined);
  }
  return out;
}

}  // namespace study
