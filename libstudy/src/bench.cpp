#include "study/bench.hpp"

#include <unistd.h>

#include <algorithm>
#include <fmt/format.h>
#include <mutex>
#include <stdexcept>

#include "awcc/parallel.hpp"
#include "awcc/process.hpp"
#include "correction/features.hpp"
#include "study/clock.hpp"
#include "study/run.hpp"
#include "synth/recording.hpp"
#include "synth/sidecar.hpp"
#include "synth/synthesiser.hpp"

namespace study {

synth::Scene bench_scene(const std::string& name) {
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
    throw std::invalid_argument(fmt::format("unknown scene '{}'; use base, high-tu, small-bubbles, low-c, short-T", name));
  }
  return s;
}

std::vector<BenchRow> bench_one(const std::string& name, std::uint64_t seed, const BenchPlan& plan,
                                const correction::CorrectionModel* model, const std::filesystem::path& scratch) {
  std::vector<BenchRow> rows;
  // (duration, fs) records: the duration series, then the rates at the base duration.
  std::vector<std::pair<double, double>> records;
  for (double d : plan.durations) records.emplace_back(d, 500e3);
  if (std::find(plan.durations.begin(), plan.durations.end(), plan.base_duration) == plan.durations.end())
    records.emplace_back(plan.base_duration, 500e3);
  for (double f : plan.rates) records.emplace_back(plan.base_duration, f);
  for (const auto& duration_and_rate : records) {
    // Named copies, not a structured binding: the lambda below uses them
    // (clang 14, which builds the fuzz targets, cannot capture a binding).
    const double duration = duration_and_rate.first, fs = duration_and_rate.second;
    synth::Scene s = bench_scene(name);
    s.duration = duration;
    s.fs = fs;
    s.seed = seed;
    const auto syn = synth::synthesise(s);
    const double dx = s.streamwise_separation(), dy = s.lateral_separation();
    const auto record = awcc::binary_recording({syn.signals[0], syn.signals[1]}, processing_options({}, dx, dy));
    const bool base = duration == plan.base_duration && fs == 500e3;
    auto row = [&](std::string method, int np) {
      BenchRow r;
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
      RunOptions fscc_alone;
      fscc_alone.run_awcc = false;
      const auto options = processing_options(fscc_alone, dx, dy);
      awcc::ProcessResult res;
      BenchRow r = row("fscc", 0);
      r.seconds = cost([&] { res = awcc::process_binarised(record, options); });
      const auto& f = *res.fscc;
      if (f.ok()) r.velocity = f.velocity;
      r.tu = f.turbulence_intensity_chanson;
      r.status = f.ok() ? "ok" : std::string(awcc::to_string(f.status));
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
    for (const auto& [method, setting] : settings) {
      RunOptions awcc_alone;
      awcc_alone.run_fscc = false;
      awcc_alone.awcc = setting;
      const auto options = processing_options(awcc_alone, dx, dy);
      awcc::ProcessResult res;
      BenchRow r = row(method, setting.np);
      r.seconds = cost([&] { res = awcc::process_binarised(record, options); });
      const auto& a = *res.awcc;
      if (a.ok()) {
        r.velocity = a.velocity;
        r.tu = a.turbulence_intensity;
      }
      r.windows = a.windows_accepted;
      r.status = a.ok() ? "ok" : std::string(awcc::to_string(a.status));
      rows.push_back(r);
      if (model && method == "awcc-intervals") {
        // The correction's cost is the processing's plus the forest's.
        BenchRow c = row("awcc-intervals+qrf", setting.np);
        correction::Correction k;
        c.seconds = r.seconds + cost([&] { k = model->correct(correction::measurement_of(res)); });
        c.windows = a.windows_accepted;
        if (k.corrected()) {
          c.velocity = k.velocity->median();
          if (k.turbulence_corrected()) c.tu = k.turbulence_intensity->median();
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
      RunOptions raw;
      raw.run_fscc = false;
      raw.awcc.signal = awcc::CorrelationSignal::raw;
      auto p = processing_options(raw, dx, dy);
      p.read_ahead = false;  // one thread: the cost is this thread's
      p.reader.volts_per_count = s.voltage_full_scale / 32768.0;
      awcc::ProcessResult res;
      BenchRow r = row("awcc-raw", 10);
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

std::vector<BenchRow> run_bench(const std::vector<std::string>& scenes, int seeds, std::uint64_t first_seed,
                                const BenchPlan& plan, const correction::CorrectionModel* model, int threads,
                                const Progress& progress) {
  struct Task {
    std::string scene;
    std::uint64_t seed;
  };
  std::vector<Task> tasks;
  for (const auto& name : scenes)
    for (int k = 0; k < seeds; ++k) tasks.push_back({name, first_seed + static_cast<std::uint64_t>(k)});
  const auto scratch = std::filesystem::temp_directory_path() / fmt::format("pdp-bench-{}", ::getpid());
  std::vector<std::vector<BenchRow>> results(tasks.size());
  try {
    std::filesystem::create_directories(scratch);
    std::mutex mutex;
    std::size_t done = 0;
    awcc::parallel_for(tasks.size(), threads, [&](std::size_t i) {
      results[i] = bench_one(tasks[i].scene, tasks[i].seed, plan, model, scratch);
      std::lock_guard lock(mutex);
      ++done;
      if (progress) progress(static_cast<double>(done) / static_cast<double>(tasks.size()));
    });
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove_all(scratch, ec);
    throw;
  }
  std::filesystem::remove_all(scratch);
  std::vector<BenchRow> out;
  for (auto& rows : results) out.insert(out.end(), rows.begin(), rows.end());
  return out;
}

std::string bench_header() {
  return "scene,seed,method,np,fs,duration,seconds,velocity,truth_velocity,velocity_error,turbulence_intensity,"
         "truth_turbulence_intensity,turbulence_intensity_error,windows_accepted,status\n";
}

std::string bench_row_text(const BenchRow& r) {
  auto n = [](const std::optional<double>& v) { return v ? fmt::format("{:.10g}", *v) : std::string(); };
  auto err = [](const std::optional<double>& v, double t) {
    return v && t != 0.0 ? fmt::format("{:.10g}", *v / t - 1.0) : std::string();
  };
  return fmt::format("{},{},{},{},{},{},{:.6f},{},{:.10g},{},{},{:.10g},{},{},{}\n", r.scene, r.seed, r.method, r.np,
                     r.fs, r.duration, r.seconds, n(r.velocity), r.truth_velocity, err(r.velocity, r.truth_velocity),
                     n(r.tu), r.truth_tu, err(r.tu, r.truth_tu), r.windows >= 0 ? std::to_string(r.windows) : std::string(),
                     r.status);
}

}  // namespace study
