// Benchmark of the bubble-probe interaction correction (issue 14,
// docs/performance.md): the accepted AWCC windows of recordings (processed
// without the correction) are corrected one by one on one thread; prints the
// windows, the total, the mean and the slowest window's time.
//
//   probe_correction_bench FILE... [--fs HZ] [--dx M]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "awcc/process.hpp"
#include "bench_util.hpp"

int main(int argc, char** argv) {
  awcc::ProcessOptions options;
  options.reader.fs = 20e3;
  options.dx = 7.15e-3;
  options.fscc = false;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--fs") && i + 1 < argc) options.reader.fs = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--dx") && i + 1 < argc) options.dx = std::atof(argv[++i]);
    else files.emplace_back(argv[i]);
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: probe_correction_bench FILE... [--fs HZ] [--dx M]\n");
    return 2;
  }
  awcc::ProbeCorrectionOptions correction;
  correction.enabled = true;
  std::size_t windows = 0, failed = 0, over_1ms = 0;
  double total = 0.0, slowest = 0.0;
  for (const auto& f : files) {
    const auto r = awcc::process_recording(f, options);
    for (const auto& w : r.awcc->windows) {
      if (w.fate != awcc::WindowFate::accepted && w.fate != awcc::WindowFate::roc) continue;
      const double t0 = bench::now();
      const auto c = awcc::correct_window(w.velocity, w.void_fraction, w.count_rate, options.dx, correction);
      const double t = bench::now() - t0;
      total += t;
      slowest = std::max(slowest, t);
      over_1ms += t > 1e-3;
      ++windows;
      failed += c.outcome == awcc::CorrectionOutcome::failed;
    }
  }
  std::printf("probe correction: %zu windows (%zu failed) in %.4f s: mean %.1f us, slowest %.1f us, %zu over 1 ms\n",
              windows, failed, total, 1e6 * total / static_cast<double>(std::max<std::size_t>(windows, 1)),
              1e6 * slowest, over_1ms);
  return 0;
}
