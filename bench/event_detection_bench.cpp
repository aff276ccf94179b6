// Benchmark of event detection on the base case (docs/performance.md).
//
//   event_detection_bench [--duration SECONDS] [--repeat N]
//
// Synthesises the base case (two tips, 500 kHz) into memory, then times
// event detection from the two binary signals on one thread with each
// pairing (Shen given the scene's mean velocity as its first estimate), and
// the pairing alone: median of N runs, leading bubbles per second.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "awcc/event_detection.hpp"
#include "bench_util.hpp"
#include "synth/synthesiser.hpp"

using bench::now;

int main(int argc, char** argv) {
  const auto args = bench::base_case_args(argc, argv);
  const double duration = args.duration;
  const int repeat = args.repeat;
  synth::Scene scene;
  scene.duration = duration;
  const auto syn = synth::synthesise(scene);
  std::printf("base case %.0f s at %.0f kHz: %zu and %zu air intervals\n", duration, scene.fs / 1e3,
              syn.signals[0].intervals.size(), syn.signals[1].intervals.size());
  for (auto pairing : {awcc::Pairing::kramer, awcc::Pairing::shen}) {
    awcc::EventOptions o;
    o.pairing = pairing;
    awcc::EventResult r;
    const double t = bench::median_seconds(repeat, [&] {
      r = awcc::event_detection(syn.signals[0], syn.signals[1], scene.dx, o, scene.velocity);
    });
    std::printf("%s: %.3f s median of %d, %lld leading bubbles (%.2f million/s, %.0f ns each), %lld paired, u = %.3f "
                "m/s, Tu = %.3f\n",
                std::string(awcc::to_string(pairing)).c_str(), t, repeat, static_cast<long long>(r.bubbles_total),
                static_cast<double>(r.bubbles_total) / t / 1e6, t / static_cast<double>(r.bubbles_total) * 1e9,
                static_cast<long long>(r.bubbles_paired), r.velocity, r.turbulence_intensity);
  }
  const auto leading = awcc::crossings(syn.signals[0]);
  const auto trailing = awcc::crossings(syn.signals[1]);
  const double t = bench::median_seconds(repeat, [&] { (void)awcc::pair_bubbles(leading, trailing, scene.dx, {}); });
  std::printf("Kramer pairing alone: %.3f s (%.0f ns per leading bubble)\n", t,
              t / static_cast<double>(leading.size()) * 1e9);
  return 0;
}
