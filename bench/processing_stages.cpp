// The processing half of a study run (bench/run_bench.cpp) stage by stage
// (docs/performance.md, issue 32): the base case synthesised once, then each
// step of awcc::process_binarised timed on its own, on one thread, median of
// N calls, and the whole processing as run_bench times it.
//
//   processing_stages [--duration SECONDS] [--repeat N] [--seed S] [--stage phase|fscc|awcc|sizes|whole]
//                     [--dump FILE.json]
#include <time.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "awcc/awcc.hpp"
#include "awcc/fscc.hpp"
#include "awcc/phase_statistics.hpp"
#include "awcc/position_sizes.hpp"
#include "awcc/serialise.hpp"
#include "bench_util.hpp"
#include "study/run.hpp"

namespace {

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  double duration = 300.0;
  int repeat = 5;
  std::uint64_t seed = 1;
  std::string only;  // one stage (its name's first word), for a profile of it
  const char* dump = nullptr;  // the whole result as JSON (every double to 17 digits), to compare two builds
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--duration") && i + 1 < argc) duration = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) seed = std::strtoull(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--stage") && i + 1 < argc) only = argv[++i];
    else if (!std::strcmp(argv[i], "--dump") && i + 1 < argc) dump = argv[++i];
  }
  synth::Scene scene;
  scene.duration = duration;
  scene.seed = seed;
  const auto syn = study::synthesise_pair(scene);
  const auto& x = syn.signals[0];
  const auto& y = syn.signals[1];
  const study::RunOptions run;
  const auto options = study::processing_options(run, scene.streamwise_separation(), scene.lateral_separation());
  const double dx = options.dx;

  std::printf("base case, %.0f s at %.0f kHz, seed %llu: processing stages, median of %d (one thread)\n", duration,
              scene.fs / 1e3, static_cast<unsigned long long>(seed), repeat);
  // Median and fastest of the calls, in CPU time of this thread: on a shared
  // machine the wall time counts the waits for a core too.
  const auto show = [](const char* name, std::pair<double, double> s) {
    if (s.first < 0.0) return;
    std::printf("  %-30s median %.4f s  fastest %.4f s\n", name, s.first, s.second);
  };
  const auto timed = [&only](const char* name, int n, auto step) {
    std::vector<double> t;
    if (!only.empty() && std::string(name).rfind(only, 0) != 0) n = 0;
    if (n == 0) return std::pair{-1.0, -1.0};
    for (int k = 0; k < n; ++k) {
      const double t0 = cpu_seconds();
      step();
      t.push_back(cpu_seconds() - t0);
    }
    return std::pair{bench::median(t), *std::min_element(t.begin(), t.end())};
  };
  awcc::PhaseStatistics phase;
  awcc::PhaseStatisticsOptions po;
  po.histogram_bins = options.histogram_bins;
  po.velocity = 10.0;
  show("phase statistics (one tip)", timed("phase", repeat, [&] { phase = awcc::phase_statistics(x, po); }));
  show("fscc (full record + interval)",
       timed("fscc", repeat, [&] { (void)awcc::fscc(x, y, dx, options.fscc_options); }));
  std::optional<awcc::AwccResult> a;
  show("awcc (interval path)", timed("awcc", repeat, [&] { a = awcc::awcc(x, y, dx, options.awcc_options); }));
  // The sizes read the leading tip's statistics and AWCC's windows.
  if (!a && (only.empty() || only == "sizes")) {
    phase = awcc::phase_statistics(x, po);
    a = awcc::awcc(x, y, dx, options.awcc_options);
  }
  show("sizes per position", timed("sizes", repeat, [&] {
         (void)awcc::position_sizes(x, phase, a, std::nullopt, a->velocity, "awcc", options.size_options);
       }));
  show("whole processing", timed("whole", repeat, [&] {
         (void)study::process_synthesis(x, y, options);
       }));
  if (dump) {
    std::ofstream(dump) << awcc::to_json(study::process_synthesis(x, y, options)).dump(1) << "\n";
  }
  return 0;
}
