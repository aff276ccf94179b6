// Benchmark of the synthetic probe (docs/performance.md).
//
//   synth_bench [--duration SECONDS] [--repeat N] [--brute-force] [--bubble-truth]
//
// Synthesises the base case (METHOD.md 5) to air intervals N times on one
// thread and prints the median wall time and the process's peak memory (run
// it once without and once with --bubble-truth, the truth per bubble, to see
// what the table costs: peak memory is the process's, so not one run). With
// --brute-force it also times the dense per-sample piercing test of the same
// scene (bubbles and velocities kept for it), and checks that both give the
// same samples.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "bench_util.hpp"
#include "synth/synthesiser.hpp"

using bench::now;
using bench::peak_mb;

int main(int argc, char** argv) {
  double duration = 300.0;
  int repeat = 3;
  bool brute = false;
  bool bubble_truth = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--duration") && i + 1 < argc) duration = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--brute-force")) brute = true;
    else if (!std::strcmp(argv[i], "--bubble-truth")) bubble_truth = true;
    else {
      std::fprintf(stderr, "usage: synth_bench [--duration SECONDS] [--repeat N] [--brute-force] [--bubble-truth]\n");
      return 2;
    }
  }
  synth::Scene scene;  // the base case
  scene.duration = duration;

  std::vector<double> times;
  std::int64_t chords = 0;
  std::size_t rows = 0;
  synth::SynthesisOptions options;
  options.bubble_truth = bubble_truth;
  for (int r = 0; r < repeat; ++r) {
    const double t0 = now();
    const auto out = synth::synthesise(scene, options);
    times.push_back(now() - t0);
    chords = static_cast<std::int64_t>(out.signals[0].intervals.size());
    if (out.bubbles) rows = out.bubbles->size();
  }
  std::sort(times.begin(), times.end());
  std::printf("base case %.0f s at %.0f kHz: %lld samples a tip, %lld chords on tip 0\n", duration, scene.fs / 1e3,
              static_cast<long long>(scene.sample_count()), static_cast<long long>(chords));
  std::printf("exact piercing to air intervals: median %.3f s over %d runs (min %.3f, max %.3f); peak memory %.0f MB\n",
              times[times.size() / 2], repeat, times.front(), times.back(), peak_mb());
  if (bubble_truth) {
    const double row_bytes = 84.0 + 48.0 * static_cast<double>(scene.probe_tips().size());
    std::printf("truth per bubble: %zu rows, %.0f MB of table (%.0f bytes a row)\n", rows,
                static_cast<double>(rows) * row_bytes / 1e6, row_bytes);
  }

  if (brute) {
    synth::SynthesisOptions o;
    o.keep_reference_data = true;
    const auto out = synth::synthesise(scene, o);
    const double t0 = now();
    const auto dense = synth::brute_force_signals(scene, *out.reference);
    const double t_brute = now() - t0;
    std::int64_t mismatches = 0;
    for (std::size_t j = 0; j < dense.size(); ++j) {
      std::vector<std::uint8_t> block(1 << 20);
      for (std::int64_t first = 0; first < scene.sample_count(); first += static_cast<std::int64_t>(block.size())) {
        const auto n = static_cast<std::size_t>(std::min<std::int64_t>(static_cast<std::int64_t>(block.size()),
                                                                       scene.sample_count() - first));
        out.signals[j].render(first, std::span<std::uint8_t>(block.data(), n));
        for (std::size_t i = 0; i < n; ++i) mismatches += block[i] != dense[j][static_cast<std::size_t>(first) + i];
      }
    }
    std::printf("dense per-sample test of the same scene: %.3f s; samples differing from the exact method: %lld\n",
                t_brute, static_cast<long long>(mismatches));
  }
  return 0;
}
