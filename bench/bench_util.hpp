#pragma once
// What the benchmark programs share: a clock, the process's peak memory and medians.

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace bench {

inline double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Peak resident memory of this process so far, MB.
inline double peak_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// The median wall time of `repeat` calls of run(), s.
template <class Run>
double median_seconds(int repeat, Run run) {
  std::vector<double> times;
  for (int k = 0; k < repeat; ++k) {
    const double t0 = now();
    run();
    times.push_back(now() - t0);
  }
  return median(times);
}

/// The base-case benchmarks' arguments: --duration SECONDS (300) and --repeat N (3).
struct BaseCaseArgs {
  double duration = 300.0;
  int repeat = 3;
};
inline BaseCaseArgs base_case_args(int argc, char** argv) {
  BaseCaseArgs out;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--duration") && i + 1 < argc) out.duration = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) out.repeat = std::atoi(argv[++i]);
  }
  return out;
}

}  // namespace bench
