// Validation of the AWCC velocity series' spectrum and integral time scale
// against libsynth's truth (issue 14, docs/validation.md).
//
//   spectrum_validation OUT_DIR [--duration S]
//
// For the base case (10 m/s, Tu 0.25, c 0.25, d_b 3 mm, dx 5 mm, 500 kHz)
// with integral time scales T = 0.01, 0.1 and 1 s: AWCC (Np = 10), the
// sample-and-hold series at the window rate, its integral time scale T_u;
// the same from the true velocity sampled at the same instants, and from the
// true window-averaged velocity (the best a window can see). Prints a table;
// writes OUT_DIR/spectra-T<value>.csv (frequency, AWCC PSD, true PSD at the
// window rate, true PSD at 16 x the window rate) for the figure.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "awcc/awcc.hpp"
#include "awcc/velocity_series.hpp"
#include "synth/synthesiser.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: spectrum_validation OUT_DIR [--duration S]\n");
    return 2;
  }
  const std::string out_dir = argv[1];
  double duration = 300.0;
  for (int i = 2; i < argc; ++i)
    if (!std::strcmp(argv[i], "--duration") && i + 1 < argc) duration = std::atof(argv[++i]);
  std::printf("| T imposed (s) | T_W (ms) | accepted windows per s | T_u AWCC, slotted (ms) | T_u AWCC, held (ms) | "
              "T + 1/nu - T/(1 + nu T) (ms) | T_u true, sampled at the window rate (ms) | T_u / T_W | Tu AWCC | Tu true "
              "|\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (double t : {0.01, 0.1, 1.0}) {
    synth::Scene scene;
    scene.time_scale = t;
    scene.duration = duration;
    synth::SynthesisOptions so;
    so.keep_velocity_history = true;
    const auto syn = synth::synthesise(scene, so);
    const auto& history = *syn.history;
    const auto a = awcc::awcc(syn.signals[0], syn.signals[1], scene.streamwise_separation(), {});
    awcc::SpectrumOptions sopt;
    const auto s = awcc::velocity_spectrum(a, duration, sopt);
    if (s.status != awcc::SpectrumStatus::ok) {
      std::printf("T = %g: %s\n", t, s.message.c_str());
      continue;
    }
    // The truth at the window instants, and window-averaged.
    std::vector<double> times, window_means;
    for (const auto& w : a.windows) {
      if (w.fate != awcc::WindowFate::accepted) continue;
      times.push_back(w.start_time + 0.5 * w.duration);
      window_means.push_back(history.mean_velocity(w.start_time, w.start_time + w.duration));
    }
    const double rate = s.resample_rate;
    const double end = std::min(times.back(), history.end_time());
    auto truth_at = [&](double r) {
      awcc::RegularSeries series;
      series.rate = r;
      for (double x = times.front(); x <= end; x += 1.0 / r) series.values.push_back(history.mean_velocity(x, x));
      return series;
    };
    const auto sampled = truth_at(rate);
    const auto fine = truth_at(16.0 * rate);
    const auto held_means = awcc::sample_and_hold(times, window_means, rate, times.front(), end);
    auto scale = [](const awcc::RegularSeries& x) {
      const auto r = awcc::autocorrelation(x.values, x.values.size() / 2);
      return awcc::integral_to_first_zero(r, 1.0 / x.rate).value_or(NAN);
    };
    double mean = 0, var = 0;
    for (double v : fine.values) mean += v;
    mean /= static_cast<double>(fine.values.size());
    for (double v : fine.values) var += (v - mean) * (v - mean);
    const double tu_true = std::sqrt(var / static_cast<double>(fine.values.size())) / mean;
    const double nu = static_cast<double>(times.size()) / (times.back() - times.front());
    (void)held_means;
    std::printf("| %g | %.2f | %.1f | %.2f | %.2f | %.2f | %.2f | %.2f | %.4f | %.4f |\n", t, 1e3 * s.mean_window_duration,
                nu, 1e3 * s.integral_time_scale.value_or(NAN), 1e3 * s.integral_time_scale_held.value_or(NAN),
                1e3 * (t + 1.0 / nu - t / (1.0 + nu * t)), 1e3 * scale(sampled), s.time_scale_ratio.value_or(NAN),
                a.turbulence_intensity, tu_true);
    const auto true_psd = awcc::welch_psd(sampled.values, sampled.rate, sopt.segment_length);
    const auto fine_psd = awcc::welch_psd(fine.values, fine.rate, 16 * sopt.segment_length);
    std::ofstream csv(out_dir + "/spectra-T" + std::to_string(t).substr(0, 4) + ".csv");
    csv << "source,frequency_Hz,psd\n";
    for (std::size_t k = 0; k < s.psd.frequency.size(); ++k) csv << "awcc," << s.psd.frequency[k] << ',' << s.psd.density[k] << '\n';
    for (std::size_t k = 0; k < true_psd.frequency.size(); ++k)
      csv << "true_window_rate," << true_psd.frequency[k] << ',' << true_psd.density[k] << '\n';
    for (std::size_t k = 0; k < fine_psd.frequency.size(); ++k)
      csv << "true_fine," << fine_psd.frequency[k] << ',' << fine_psd.density[k] << '\n';
    csv << "resolvable," << s.resolvable_frequency << ",0\n";
  }
  return 0;
}
