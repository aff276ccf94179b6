#include "bench_command.hpp"

#include <algorithm>
#include <ctime>
#include <mutex>
#include <unistd.h>
#include <chrono>
#include <filesystem>
#include <fmt/format.h>
#include <sstream>
#include <spdlog/spdlog.h>

#include "awcc/atomic_output.hpp"
#include "awcc/order_statistics.hpp"
#include "awcc/units.hpp"
#include "awcc/parallel.hpp"
#include "awcc/phase_statistics.hpp"
#include "awcc/process.hpp"
#include "correction/features.hpp"
#include "correction/model.hpp"
#include "study.hpp"
#include "synth/recording.hpp"
#include "synth/sidecar.hpp"
#include "synth/synthesiser.hpp"
#include "terminal.hpp"

namespace pdp {

void setup_bench(CLI::App& app, Command& command, BenchOptions& o) {
  auto* cmd = app.add_subcommand("bench", "Error against cost of every method and setting on fixed scenes, over seeds");
  command.app = cmd;
  add_config_option(command);
  command.required.push_back(cmd->add_option("-o,--output", o.output, "CSV: one row per scene, seed and setting"));
  cmd->add_option("--seeds", o.seeds, "seeds per scene; RMS error, bias and spread are over these")
      ->check(CLI::Range(1, 1000))->capture_default_str();
  cmd->add_option("--first-seed", o.first_seed, "the first seed")->capture_default_str();
  cmd->add_option("--scenes", o.scenes, "scenes: base, high-tu, small-bubbles, low-c, short-T")->capture_default_str();
  cmd->add_option("--durations", o.durations, "record lengths of the duration series (500 kHz, Np = 10), each 0.1s to 1h")
      ->capture_default_str();
  cmd->add_option("--duration", o.duration, "record length of the Np, fs and raw-voltage settings (0.1s to 1h)")
      ->capture_default_str();
  cmd->add_option("--correct", o.correct, "correction model (.qrf): adds the corrected AWCC of every interval-path setting");
  cmd->add_option("--threads", o.threads, "worker threads (0 = all cores); the numbers do not depend on it")
      ->check(CLI::Range(0, 4096))->capture_default_str();
  cmd->add_flag("--quick", o.quick, "short records, two seeds and few settings (for tests)");
}

namespace {

synth::Scene named_scene(const std::string& name) {
  synth::Scene s;
  if (name == "high-tu") {
    s.tu = 0.35;
    s.tu_y = s.tu_z = 0.175;
  } else if (name == "small-bubbles") {
    s.bubble_diameter = 1e-3;
  } else if (name == "low-c") {
    s.void_fraction = 0.02;
  } else if (name == "short-T") {
    s.time_scale = 5e-3;
  } else if (name != "base") {
    throw std::invalid_argument(fmt::format("--scenes: unknown scene '{}'; use base, high-tu, small-bubbles, low-c, short-T", name));
  }
  return s;
}

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(item);
  return out;
}

double record_length(const std::string& text, const std::string& option) {
  double d = 0.0;
  try {
    d = awcc::parse_quantity(text, awcc::Dimension::time);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("{}: {}", option, e.what()));
  }
  if (!(d >= 0.1 && d <= 3600.0)) throw std::invalid_argument(fmt::format("{} {}: give 0.1s to 1h", option, text));
  return d;
}

struct Row {
  std::string scene, method;
  std::uint64_t seed = 0;
  int np = 10;
  double duration = 0, fs = 0, seconds = 0;
  std::optional<double> velocity, tu;
  double truth_velocity = 0, truth_tu = 0;
  std::int64_t windows = -1;
  std::string status;  ///< ok, or why there is no value
};

constexpr const char* header =
    "scene,seed,method,np,fs,duration,seconds,velocity,truth_velocity,velocity_error,turbulence_intensity,"
    "truth_turbulence_intensity,turbulence_intensity_error,windows_accepted,status\n";

std::string csv_row(const Row& r) {
  auto n = [](const std::optional<double>& v) { return v ? fmt::format("{:.10g}", *v) : std::string(); };
  auto err = [](const std::optional<double>& v, double t) {
    return v && t != 0.0 ? fmt::format("{:.10g}", *v / t - 1.0) : std::string();
  };
  return fmt::format("{},{},{},{},{},{},{:.6f},{},{:.10g},{},{},{:.10g},{},{},{}\n", r.scene, r.seed, r.method, r.np,
                     r.fs, r.duration, r.seconds, n(r.velocity), r.truth_velocity, err(r.velocity, r.truth_velocity),
                     n(r.tu), r.truth_tu, err(r.tu, r.truth_tu), r.windows >= 0 ? std::to_string(r.windows) : std::string(),
                     r.status);
}

struct Plan {
  std::vector<double> durations;  // the duration series (500 kHz, Np = 10)
  double base_duration = 60.0;    // the Np, fs and raw settings
  std::vector<int> nps;           // besides 10, at the base duration
  std::vector<double> rates;      // besides 500 kHz, at the base duration
  bool raw = true;
};

// Every setting of one scene and seed; rows in a fixed order.
std::vector<Row> bench_one(const std::string& name, std::uint64_t seed, const Plan& plan,
                           const correction::CorrectionModel* model, const std::filesystem::path& scratch) {
  std::vector<Row> rows;
  // (duration, fs) records: the duration series, then the rates at the base duration.
  std::vector<std::pair<double, double>> records;
  for (double d : plan.durations) records.emplace_back(d, 500e3);
  if (std::find(plan.durations.begin(), plan.durations.end(), plan.base_duration) == plan.durations.end())
    records.emplace_back(plan.base_duration, 500e3);
  for (double f : plan.rates) records.emplace_back(plan.base_duration, f);
  for (const auto& [duration, fs] : records) {
    synth::Scene s = named_scene(name);
    s.duration = duration;
    s.fs = fs;
    s.seed = seed;
    const auto syn = synth::synthesise(s);
    const auto& a = syn.signals[0];
    const auto& b = syn.signals[1];
    const auto phase = awcc::phase_statistics(a);
    const bool base = duration == plan.base_duration && fs == 500e3;
    auto row = [&](std::string method, int np) {
      Row r;
      r.scene = name;
      r.seed = seed;
      r.method = std::move(method);
      r.np = np;
      r.duration = duration;
      r.fs = fs;
      r.truth_velocity = syn.truth.realised.mean_velocity[0];
      r.truth_tu = syn.truth.realised.turbulence_intensity[0];
      return r;
    };
    {
      awcc::FsccResult res;
      Row r = row("fscc", 0);
      r.seconds = cost([&] { res = awcc::fscc(a, b, s.dx, {}); });
      if (res.ok()) r.velocity = res.velocity;
      r.tu = res.turbulence_intensity_chanson;
      r.status = res.ok() ? "ok" : std::string(awcc::to_string(res.status));
      rows.push_back(r);
    }
    std::vector<std::pair<std::string, awcc::AwccOptions>> settings;
    settings.push_back({"awcc-intervals", {}});
    if (fs == 500e3) {
      awcc::AwccOptions fft;
      fft.path = awcc::CorrelationPath::fft;
      settings.push_back({"awcc-fft", fft});
    }
    if (base) {
      for (int np : plan.nps) {
        awcc::AwccOptions x;
        x.np = np;
        settings.push_back({"awcc-intervals", x});
      }
    }
    for (const auto& [method, options] : settings) {
      awcc::AwccResult res;
      Row r = row(method, options.np);
      r.seconds = cost([&] { res = awcc::awcc(a, b, s.dx, options); });
      if (res.ok()) {
        r.velocity = res.velocity;
        r.tu = res.turbulence_intensity;
      }
      r.windows = res.windows_accepted;
      r.status = res.ok() ? "ok" : std::string(awcc::to_string(res.status));
      rows.push_back(r);
      if (model && method == "awcc-intervals") {
        // The correction's cost is AWCC's plus the forest's.
        Row c = row("awcc-intervals+qrf", options.np);
        correction::Correction k;
        const auto m = awcc_measurement(res, phase, s.dx, s.dy, options.np, fs, duration);
        c.seconds = r.seconds + cost([&] { k = model->correct(m); });
        c.windows = res.windows_accepted;
        if (k.corrected()) {
          c.velocity = k.velocity->median();
          c.tu = k.turbulence_intensity->median();
          c.status = "ok";
        } else {
          c.status = std::string(correction::to_string(k.status));
        }
        rows.push_back(c);
      }
    }
    // Raw-voltage AWCC, from a recording as a lab runs it (reading and
    // binarising the file included in its cost).
    if (base && plan.raw) {
      const auto file = scratch / fmt::format("{}-{}.w64", name, seed);
      synth::RecordingOptions ro;
      ro.signal = synth::SignalKind::voltage;
      ro.format = synth::FileFormat::w64;
      synth::write_recording(file, s, syn.signals, ro);
      awcc::ProcessOptions p;
      p.dx = s.dx;
      p.fscc = false;
      p.read_ahead = false;  // one thread: the cost is this thread's
      p.structure.enabled = false;
      p.velocity_spectrum = false;
      p.awcc_options.signal = awcc::CorrelationSignal::raw;
      p.reader.volts_per_count = s.voltage_full_scale / 32768.0;
      awcc::ProcessResult res;
      Row r = row("awcc-raw", 10);
      r.seconds = cost([&] { res = awcc::process_recording(file, p); });
      if (res.awcc && res.awcc->ok()) {
        r.velocity = res.awcc->velocity;
        r.tu = res.awcc->turbulence_intensity;
      }
      r.windows = res.awcc ? res.awcc->windows_accepted : -1;
      r.status = res.awcc && res.awcc->ok() ? "ok" : (res.awcc ? std::string(awcc::to_string(res.awcc->status)) : "not run");
      rows.push_back(r);
      std::filesystem::remove(file);
      std::filesystem::remove(synth::sidecar_path(file));
    }
  }
  return rows;
}

}  // namespace

int run_bench(const BenchOptions& o) {
  std::vector<std::string> scenes = split(o.scenes);
  Plan plan;
  std::optional<correction::CorrectionModel> model;
  try {
    for (const auto& name : scenes) named_scene(name);
    plan.base_duration = record_length(o.duration, "--duration");
    for (const auto& d : split(o.durations)) plan.durations.push_back(record_length(d, "--durations"));
    if (plan.durations.empty()) throw std::invalid_argument("--durations: give at least one record length");
    if (!o.correct.empty()) {
      model = correction::CorrectionModel::load(o.correct);
      if (const auto why = model->mismatch(correction::processing_of(awcc::AwccOptions{})); !why.empty()) {
        throw std::invalid_argument(fmt::format("--correct {}: the model was trained on results processed otherwise "
                                                "({}); pdp bench runs AWCC's defaults",
                                                o.correct, why));
      }
    }
  } catch (const std::exception& e) {
    return report_error(e);
  }
  int seeds = o.seeds;
  if (o.quick) {
    plan.durations = {1.0, 2.0};
    plan.base_duration = std::min(plan.base_duration, 2.0);
    plan.nps = {5};
    plan.rates = {100e3};
    seeds = std::min(seeds, 2);
  } else {
    plan.nps = {5, 15, 20, 30};
    plan.rates = {20e3, 100e3, 2e6};
  }
  struct Task {
    std::string scene;
    std::uint64_t seed;
  };
  std::vector<Task> tasks;
  for (const auto& name : scenes)
    for (int k = 0; k < seeds; ++k) tasks.push_back({name, o.first_seed + static_cast<std::uint64_t>(k)});
  const auto scratch = std::filesystem::temp_directory_path() / fmt::format("pdp-bench-{}", ::getpid());
  std::vector<std::vector<Row>> results(tasks.size());
  try {
    std::filesystem::create_directories(scratch);
    spdlog::info("pdp bench: {} scenes x {} seeds, {} records each", scenes.size(), seeds,
                 plan.durations.size() + plan.rates.size() + 1);
    Progress progress("benchmarking");
    std::mutex mutex;
    std::size_t done = 0;
    awcc::parallel_for(tasks.size(), o.threads, [&](std::size_t i) {
      results[i] = bench_one(tasks[i].scene, tasks[i].seed, plan, model ? &*model : nullptr, scratch);
      std::lock_guard lock(mutex);
      progress(static_cast<double>(++done) / static_cast<double>(tasks.size()));
    });
    std::filesystem::remove_all(scratch);
    std::string out = header;
    for (const auto& rows : results)
      for (const auto& r : rows) out += csv_row(r);
    awcc::write_text_atomically(o.output, out);
  } catch (const std::exception& e) {
    std::error_code ec;
    std::filesystem::remove_all(scratch, ec);
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
