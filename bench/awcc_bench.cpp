// Benchmark of AWCC on the base case (docs/performance.md).
//
//   awcc_bench [--duration SECONDS] [--repeat N]
//
// Synthesises the base case (two tips, 500 kHz) into memory, then times AWCC
// from the two binary signals on one thread with the default (interval) path
// and the FFT path: median of N runs, windows per second, and the growth of
// the process's peak memory during AWCC.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "awcc/awcc.hpp"
#include "bench_util.hpp"
#include "synth/synthesiser.hpp"

using bench::now;
using bench::peak_mb;

int main(int argc, char** argv) {
  const auto args = bench::base_case_args(argc, argv);
  const double duration = args.duration;
  const int repeat = args.repeat;
  synth::Scene scene;
  scene.duration = duration;
  const auto syn = synth::synthesise(scene);
  const double before = peak_mb();
  std::printf("base case %.0f s at %.0f kHz; memory after synthesis %.0f MB\n", duration, scene.fs / 1e3, before);
  for (auto path : {awcc::CorrelationPath::intervals, awcc::CorrelationPath::fft}) {
    awcc::AwccOptions o;
    o.path = path;
    std::vector<double> times;
    awcc::AwccResult r;
    for (int k = 0; k < repeat; ++k) {
      const double t0 = now();
      r = awcc::awcc(syn.signals[0], syn.signals[1], scene.dx, o);
      times.push_back(now() - t0);
    }
    std::sort(times.begin(), times.end());
    const double t = times[times.size() / 2];
    std::printf("%s path: %.3f s median of %d, %lld windows (%.0f windows/s), %lld accepted, u = %.4f m/s, Tu = %.4f; "
                "peak memory now %.0f MB\n",
                path == awcc::CorrelationPath::intervals ? "interval (default)" : "FFT", t, repeat,
                static_cast<long long>(r.windows_total), static_cast<double>(r.windows_total) / t,
                static_cast<long long>(r.windows_accepted), r.velocity, r.turbulence_intensity, peak_mb());
  }
  return 0;
}
