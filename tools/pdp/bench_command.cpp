#include "bench_command.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fmt/format.h>
#include <sstream>
#include <spdlog/spdlog.h>

#include "awcc/atomic_output.hpp"
#include "awcc/order_statistics.hpp"
#include "awcc/units.hpp"
#include "awcc/process.hpp"
#include "synth/recording.hpp"
#include "synth/synthesiser.hpp"
#include "terminal.hpp"

namespace pdp {

void setup_bench(CLI::App& app, Command& command, BenchOptions& o) {
  auto* cmd = app.add_subcommand("bench", "Error against run time of every method and setting on fixed scenes");
  command.app = cmd;
  add_config_option(command);
  command.required.push_back(cmd->add_option("-o,--output", o.output, "CSV of timings and errors"));
  cmd->add_option("--repeat", o.repeat, "timings per setting; the median is kept")->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--scenes", o.scenes, "scenes: base, high-tu, small-bubbles, low-c, short-T")->capture_default_str();
  cmd->add_option("--duration", o.duration, "record length of the method settings (0.1s to 1h)")
      ->capture_default_str();
  cmd->add_flag("--quick", o.quick, "short records and fewer settings (for tests)");
}

namespace {

using clock_type = std::chrono::steady_clock;

double median_time(int repeat, const std::function<void()>& f) {
  std::vector<double> t;
  for (int i = 0; i < repeat; ++i) {
    const auto s = clock_type::now();
    f();
    t.push_back(std::chrono::duration<double>(clock_type::now() - s).count());
  }
  return awcc::median(t);
}

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

struct Row {
  std::string scene, method, setting;
  double duration = 0, fs = 0, seconds = 0;
  std::optional<double> velocity, tu;
  double truth_velocity = 0, truth_tu = 0;
  std::int64_t windows = -1;
};

std::string csv_row(const Row& r) {
  auto n = [](const std::optional<double>& v) { return v ? fmt::format("{:.10g}", *v) : std::string(); };
  auto err = [](const std::optional<double>& v, double t) {
    return v && t != 0.0 ? fmt::format("{:.10g}", *v / t - 1.0) : std::string();
  };
  return fmt::format("{},{},{},{},{},{:.6f},{},{:.10g},{},{},{:.10g},{},{}\n", r.scene, r.method, r.setting, r.duration,
                     r.fs, r.seconds, n(r.velocity), r.truth_velocity, err(r.velocity, r.truth_velocity), n(r.tu),
                     r.truth_tu, err(r.tu, r.truth_tu), r.windows >= 0 ? std::to_string(r.windows) : std::string());
}

}  // namespace

int run_bench(const BenchOptions& o) {
  std::vector<std::string> scenes;
  {
    std::stringstream in(o.scenes);
    std::string item;
    while (std::getline(in, item, ',')) scenes.push_back(item);
  }
  std::string out =
      "scene,method,setting,duration,fs,seconds,velocity,truth_velocity,velocity_error,turbulence_intensity,"
      "truth_turbulence_intensity,turbulence_intensity_error,windows_accepted\n";
  double method_duration = 0.0;
  try {
    for (const auto& name : scenes) named_scene(name);
    try {
      method_duration = awcc::parse_quantity(o.duration, awcc::Dimension::time);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("--duration: {}", e.what()));
    }
    if (!(method_duration >= 0.1 && method_duration <= 3600.0)) {
      throw std::invalid_argument(fmt::format("--duration {}: give 0.1s to 1h", o.duration));
    }
  } catch (const std::invalid_argument& e) {
    return report_error(e);
  }
  const double base_duration = o.quick ? std::min(method_duration, 2.0) : method_duration;
  const std::vector<double> durations = o.quick ? std::vector<double>{1.0, 2.0} : std::vector<double>{10, 30, 100, 300};
  const std::vector<double> rates = o.quick ? std::vector<double>{100e3, 500e3}
                                            : std::vector<double>{20e3, 100e3, 500e3, 2e6};
  const std::vector<int> nps = o.quick ? std::vector<int>{5, 10} : std::vector<int>{5, 10, 15, 20, 30};
  const auto scratch = std::filesystem::temp_directory_path() / fmt::format("pdp-bench-{}", ::getpid());
  std::filesystem::create_directories(scratch);
  try {
    Progress progress("benchmarking");
    std::size_t done = 0;
    for (const auto& name : scenes) {
      // (duration, fs) combinations: the method settings at the base record,
      // then durations at 500 kHz and rates at the base duration (base scene only).
      std::vector<std::pair<double, double>> records{{base_duration, 500e3}};
      if (name == "base") {
        for (double d : durations)
          if (d != base_duration) records.emplace_back(d, 500e3);
        for (double f : rates)
          if (f != 500e3) records.emplace_back(base_duration, f);
      }
      for (const auto& record : records) {
        // Plain copies: lambdas below capture them (clang 14 cannot capture bindings).
        const double duration = record.first, fs = record.second;
        synth::Scene s = named_scene(name);
        s.duration = duration;
        s.fs = fs;
        const auto syn = synth::synthesise(s);
        const auto& a = syn.signals[0];
        const auto& b = syn.signals[1];
        const double truth_u = syn.truth.realised.mean_velocity[0];
        const double truth_tu = syn.truth.realised.turbulence_intensity[0];
        const bool full = duration == base_duration && fs == 500e3;
        auto base_row = [&](std::string method, std::string setting) {
          Row r;
          r.scene = name;
          r.method = std::move(method);
          r.setting = std::move(setting);
          r.duration = duration;
          r.fs = fs;
          r.truth_velocity = truth_u;
          r.truth_tu = truth_tu;
          return r;
        };
        // FSCC.
        for (int segments : full ? std::vector<int>{1, 15} : std::vector<int>{1}) {
          awcc::FsccOptions f;
          f.segments = segments;
          awcc::FsccResult res;
          Row r = base_row("fscc", segments == 1 ? "full" : "segmented-15");
          r.seconds = median_time(o.repeat, [&] { res = awcc::fscc(a, b, s.dx, f); });
          if (res.ok()) r.velocity = res.velocity;
          r.tu = res.turbulence_intensity_chanson;
          out += csv_row(r);
        }
        // AWCC settings.
        struct Setting {
          std::string method, label;
          awcc::AwccOptions options;
        };
        std::vector<Setting> settings;
        settings.push_back({"awcc", "intervals np=10", {}});
        if (full) {
          awcc::AwccOptions fft;
          fft.path = awcc::CorrelationPath::fft;
          settings.push_back({"awcc-fft", "fft np=10", fft});
          for (int np : nps) {
            if (np == 10) continue;
            awcc::AwccOptions x;
            x.np = np;
            settings.push_back({"awcc", fmt::format("intervals np={}", np), x});
          }
          awcc::AwccOptions par;
          par.subsample = awcc::Subsample::parabolic;
          settings.push_back({"awcc", "intervals np=10 parabolic", par});
        }
        for (const auto& st : settings) {
          awcc::AwccResult res;
          Row r = base_row(st.method, st.label);
          r.seconds = median_time(o.repeat, [&] { res = awcc::awcc(a, b, s.dx, st.options); });
          if (res.ok()) {
            r.velocity = res.velocity;
            r.tu = res.turbulence_intensity;
          }
          r.windows = res.windows_accepted;
          out += csv_row(r);
        }
        // Raw-voltage correlation: from a recording, as a lab runs it (the
        // time includes reading and binarising the file).
        if (full) {
          const auto file = scratch / "raw.w64";
          synth::RecordingOptions ro;
          ro.signal = synth::SignalKind::voltage;
          ro.format = synth::FileFormat::w64;
          synth::write_recording(file, s, syn.signals, ro);
          awcc::ProcessOptions p;
          p.dx = s.dx;
          p.fscc = false;
          p.awcc = true;
          p.awcc_options.signal = awcc::CorrelationSignal::raw;
          p.reader.volts_per_count = s.voltage_full_scale / 32768.0;
          awcc::ProcessResult res;
          Row r = base_row("awcc-raw", "raw voltage np=10 (incl. reading)");
          r.seconds = median_time(o.repeat, [&] { res = awcc::process_recording(file, p); });
          if (res.awcc && res.awcc->ok()) {
            r.velocity = res.awcc->velocity;
            r.tu = res.awcc->turbulence_intensity;
          }
          r.windows = res.awcc ? res.awcc->windows_accepted : -1;
          out += csv_row(r);
          std::filesystem::remove(file);
        }
        progress(static_cast<double>(++done) / static_cast<double>(scenes.size() + records.size() - 1));
      }
    }
    std::filesystem::remove_all(scratch);
    awcc::write_text_atomically(o.output, out);
  } catch (const std::exception& e) {
    std::error_code ec;
    std::filesystem::remove_all(scratch, ec);
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
