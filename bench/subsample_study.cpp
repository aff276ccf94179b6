// The sub-sample peak study (METHOD 4.3, issue 51; docs/validation.md "The
// sub-sample peak"): bias and spread of each peak estimator of
// awcc/subsample_peak.hpp against the true lag's sub-sample phase, on the
// accepted AWCC windows of libsynth scenes.
//
//   subsample_study [--scenes N] [--seed S] [--out windows.csv]
//
// The truth of a window. The realisation step does not depend on the
// sampling rate, so the same scene synthesised at M fs holds the same
// bubbles sampled M times finer (checked: the coarse signal is the fine one
// decimated, up to the interfaces that fall between samples). A window's
// reference lag is the peak of its exact (interval-path) correlation at
// M fs over the same time span, divided by M: the lag an estimator at fs
// tries to recover, to 1 / M sample. M is chosen so that M fs >= 20 MHz.
//
// Scenes: fs in {10, 20, 40, 500} kHz; u log-uniform 2-15 m/s (so that the
// lag's phase covers the sample), Tu uniform 0.02-0.35, spheres of d_b
// log-uniform 1-10 mm, Np uniform 5-30, c 0.05-0.3, dx 5 mm, dy 0-1 mm,
// T_x 0.05-0.5 s; duration set for about 400 windows (at most 60 s).
// Printed: per fs and estimator, the mean error (samples), its rms, the
// largest bias over ten bins of the phase, and what each does to the scenes'
// AWCC u and Tu against the reference lags' (mean relative errors).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "awcc/awcc.hpp"
#include "awcc/detail/awcc_steps.hpp"
#include "awcc/subsample_peak.hpp"
#include "synth/synthesiser.hpp"

namespace {

constexpr std::array<awcc::Subsample, 5> kMethods{awcc::Subsample::none, awcc::Subsample::parabolic,
                                                 awcc::Subsample::gaussian, awcc::Subsample::triangle,
                                                 awcc::Subsample::centroid};
constexpr int kBins = 10;

struct Tally {
  double sum = 0, sum2 = 0;
  long n = 0;
  std::array<double, kBins> bin_sum{};
  std::array<long, kBins> bin_n{};
  // Per-scene relative errors of u and Tu against the reference lags'.
  double u_sum = 0, u_abs = 0, tu_sum = 0, tu_abs = 0;
  int scenes = 0;
};

struct Moments {
  double mean = 0, tu = 0;
};

Moments moments(const std::vector<double>& u, const std::vector<double>& w) {
  double sw = 0, su = 0;
  for (std::size_t i = 0; i < u.size(); ++i) sw += w[i], su += w[i] * u[i];
  const double mean = su / sw;
  double s2 = 0;
  for (std::size_t i = 0; i < u.size(); ++i) s2 += w[i] * (u[i] - mean) * (u[i] - mean);
  return {mean, std::sqrt(s2 / sw) / mean};
}

}  // namespace

int main(int argc, char** argv) {
  int scenes = 60;
  unsigned seed = 20261205;
  const char* out_path = nullptr;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--scenes")) scenes = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--seed")) seed = static_cast<unsigned>(std::atol(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--out")) out_path = argv[i + 1];
    else {
      std::fprintf(stderr, "usage: subsample_study [--scenes N] [--seed S] [--out windows.csv]\n");
      return 2;
    }
  }
  std::FILE* out = out_path ? std::fopen(out_path, "w") : nullptr;
  if (out_path && !out) {
    std::fprintf(stderr, "subsample_study: cannot write %s\n", out_path);
    return 1;
  }
  if (out) std::fprintf(out, "fs,scene,lag_reference,phase,method,error\n");
  const std::array<double, 4> rates{10e3, 20e3, 40e3, 500e3};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  auto log_uniform = [&](double a, double b) { return a * std::exp(std::log(b / a) * uni(rng)); };
  std::array<std::array<Tally, kMethods.size()>, rates.size()> tally{};
  long windows = 0;
  for (int s = 0; s < scenes; ++s) {
    for (std::size_t f = 0; f < rates.size(); ++f) {
      synth::Scene scene;
      scene.fs = rates[f];
      scene.velocity = log_uniform(2.0, 15.0);
      scene.tu = 0.02 + 0.33 * uni(rng);
      scene.tu_y = scene.tu_z = 0.5 * scene.tu;
      scene.time_scale = log_uniform(0.05, 0.5);
      scene.bubble_diameter = log_uniform(1e-3, 10e-3);
      scene.void_fraction = 0.05 + 0.25 * uni(rng);
      scene.dx = 5e-3;
      scene.dy = 1e-3 * uni(rng);
      scene.seed = rng();
      const int np = 5 + static_cast<int>(26 * uni(rng));
      const double window = np * scene.bubble_diameter / (1.5 * scene.velocity * scene.void_fraction);
      scene.duration = std::min(60.0, 400 * window);
      const int m = static_cast<int>(std::ceil(20e6 / scene.fs));
      synth::Scene fine = scene;
      fine.fs = scene.fs * m;
      const auto coarse = synth::synthesise(scene);
      const auto sharp = synth::synthesise(fine);
      awcc::AwccOptions o;
      o.np = np;
      const auto result = awcc::awcc(coarse.signals[0], coarse.signals[1], scene.dx, o);
      if (result.windows_accepted < 10) continue;
      awcc::AwccWorkspace workspace;
      std::array<std::vector<double>, kMethods.size()> u;
      std::vector<double> u_ref, weight;
      for (const auto& w : result.windows) {
        if (w.fate != awcc::WindowFate::accepted) continue;
        const std::int64_t k = w.lag_samples;
        const std::int64_t reach = std::max<std::int64_t>(4, k);  // the centroid's walk
        const std::int64_t first = std::max<std::int64_t>(1 - w.length, k - reach);
        const std::int64_t last = std::min<std::int64_t>(w.length - 1, k + reach);
        const auto r = awcc::detail::window_correlation_piecewise(coarse.signals[0], coarse.signals[1], w.start,
                                                                  w.length, first, last, workspace);
        const auto rf = awcc::detail::window_correlation_piecewise(
            sharp.signals[0], sharp.signals[1], w.start * m, w.length * m, (k - 2) * m, (k + 2) * m, workspace);
        if (r.empty() || rf.empty()) continue;
        const auto top = std::max_element(rf.values.begin(), rf.values.end()) - rf.values.begin();
        const double reference = static_cast<double>(rf.lags[static_cast<std::size_t>(top)]) / m;
        if (!(reference > 0.0)) continue;
        const double phase = reference - std::round(reference);
        const int bin = std::clamp(static_cast<int>((phase + 0.5) * kBins), 0, kBins - 1);
        u_ref.push_back(scene.dx * scene.fs / reference);
        weight.push_back(w.duration);
        ++windows;
        for (std::size_t j = 0; j < kMethods.size(); ++j) {
          const double lag =
              static_cast<double>(k) +
              awcc::subsample_offset(kMethods[j], [&](std::int64_t at) { return r.at(at); }, k, first, last);
          const double e = lag - reference;
          auto& t = tally[f][j];
          t.sum += e, t.sum2 += e * e, ++t.n;
          t.bin_sum[static_cast<std::size_t>(bin)] += e, ++t.bin_n[static_cast<std::size_t>(bin)];
          u[j].push_back(scene.dx * scene.fs / lag);
          if (out) {
            std::fprintf(out, "%.0f,%d,%.4f,%.4f,%s,%.5f\n", scene.fs, s, reference, phase,
                         std::string(awcc::to_string(kMethods[j])).c_str(), e);
          }
        }
      }
      if (u_ref.size() < 10) continue;
      const auto ref = moments(u_ref, weight);
      for (std::size_t j = 0; j < kMethods.size(); ++j) {
        const auto est = moments(u[j], weight);
        auto& t = tally[f][j];
        const double du = est.mean / ref.mean - 1, dtu = est.tu / ref.tu - 1;
        t.u_sum += du, t.u_abs += std::abs(du), t.tu_sum += dtu, t.tu_abs += std::abs(dtu), ++t.scenes;
      }
    }
    std::fprintf(stderr, "scene %d of %d: %ld windows so far\n", s + 1, scenes, windows);
  }
  if (out) std::fclose(out);
  std::printf("%-7s %-10s %9s %9s %9s %9s %9s %9s %9s %7s\n", "fs", "estimator", "mean", "rms", "max|bin|", "u mean",
              "|u|", "Tu mean", "|Tu|", "windows");
  for (std::size_t f = 0; f < rates.size(); ++f) {
    for (std::size_t j = 0; j < kMethods.size(); ++j) {
      const auto& t = tally[f][j];
      if (t.n == 0) continue;
      const double mean = t.sum / static_cast<double>(t.n);
      double worst = 0;
      for (int b = 0; b < kBins; ++b) {
        if (t.bin_n[static_cast<std::size_t>(b)] > 0)
          worst = std::max(worst, std::abs(t.bin_sum[static_cast<std::size_t>(b)] /
                                           static_cast<double>(t.bin_n[static_cast<std::size_t>(b)])));
      }
      const double sc = std::max(1, t.scenes);
      std::printf("%-7.0f %-10s %+9.4f %9.4f %9.4f %+8.3f%% %8.3f%% %+8.2f%% %8.2f%% %7ld\n", rates[f] / 1e3,
                  std::string(awcc::to_string(kMethods[j])).c_str(), mean,
                  std::sqrt(t.sum2 / static_cast<double>(t.n)), worst, 100 * t.u_sum / sc, 100 * t.u_abs / sc,
                  100 * t.tu_sum / sc, 100 * t.tu_abs / sc, t.n);
    }
  }
  std::printf("(errors in samples, against each window's lag from the same bubbles at >= 20 MHz; u and Tu: mean and "
              "mean |relative error| per scene against the reference lags' moments)\n");
  return 0;
}
