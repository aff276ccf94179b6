#pragma once
// What the benchmark programs share: a clock, the process's peak memory and medians.

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
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

/// Drops a file's pages from the page cache (no privilege needed: the pages
/// are clean), so that the next read of it comes from the disk. Exits when
/// the file cannot be opened: a cold measurement that read from the cache
/// would be silently wrong.
inline void evict(const char* path) {
  const int fd = ::open(path, O_RDONLY);
  if (fd < 0 || ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED) != 0) {
    std::perror(path);
    std::exit(2);
  }
  ::close(fd);
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
