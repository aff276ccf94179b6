// One study run end to end (docs/performance.md, issue 17): synthesis and
// processing (phase statistics, FSCC and AWCC together, as pdp process) of
// the base case (METHOD 5) as pdp sweep runs it, on one thread.
//
//   run_bench [--scene FILE.toml] [--duration SECONDS] [--repeat N] [--seed S]
//             [--allocator-defaults]
//
// The allocator keeps freed memory for the next run, as in pdp
// (awcc::keep_freed_memory); --allocator-defaults measures glibc's defaults,
// under which every run faults its pages in again.
//
// Prints the median (and range) of each stage over N runs, the first run
// alone (the only one that faults its pages in), and a fingerprint
// of the results: every estimate and the truth written with 17 significant
// digits, then a hash of them, so that a faster build can be checked to give
// bit-identical numbers for the same seed.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "awcc/memory.hpp"
#include "awcc/sha256.hpp"
#include "bench_util.hpp"
#include "study/run.hpp"

namespace {

struct Stage {
  const char* name;
  std::vector<double> seconds;
};

void show(const Stage& s) {
  auto v = s.seconds;
  std::sort(v.begin(), v.end());
  std::printf("  %-10s median %.3f s  (%.3f-%.3f)\n", s.name, v[v.size() / 2], v.front(), v.back());
}

std::string fingerprint(const study::RunResult& r) {
  std::string text = fmt::format("truth u {:.17g} Tu {:.17g} c {:.17g} F {:.17g}\n", r.truth_velocity,
                                 r.truth_turbulence_intensity, r.truth_void_fraction, r.truth_count_rate);
  const auto& p = r.processed;
  text += fmt::format("phase c {:.17g} F {:.17g}\n", p.tips[0].phase.void_fraction, p.tips[0].phase.bubble_count_rate);
  if (p.fscc) text += fmt::format("fscc u {:.17g} lag {:.17g} r12 {:.17g}\n", p.fscc->velocity, p.fscc->lag,
                                  p.fscc->r12_max);
  if (p.awcc) {
    text += fmt::format("awcc u {:.17g} Tu {:.17g} windows {} accepted {}\n", p.awcc->velocity,
                        p.awcc->turbulence_intensity, p.awcc->windows_total, p.awcc->windows_accepted);
  }
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  double duration = 300.0;
  int repeat = 5;
  std::uint64_t seed = 1;
  const char* scene_file = nullptr;
  bool allocator_defaults = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--scene") && i + 1 < argc) scene_file = argv[++i];
    else if (!std::strcmp(argv[i], "--duration") && i + 1 < argc) duration = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) seed = std::strtoull(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--allocator-defaults")) allocator_defaults = true;
  }
  const bool kept = !allocator_defaults && awcc::keep_freed_memory();
  synth::Scene scene;
  if (scene_file) synth::load_scene_toml(scene_file, scene);
  scene.duration = duration;
  scene.seed = seed;
  study::RunOptions options;  // as pdp sweep: FSCC and AWCC, window truth kept
  Stage synth{"synthesis", {}}, process{"processing", {}}, total{"total", {}};
  std::string first;
  for (int k = 0; k < repeat; ++k) {
    const double t0 = bench::now();
    const auto r = study::run_scene(scene, options);
    total.seconds.push_back(bench::now() - t0);
    synth.seconds.push_back(r.seconds_synth);
    process.seconds.push_back(r.seconds_process);
    const auto text = fingerprint(r);
    if (k == 0) first = text;
    else if (text != first) {
      std::fprintf(stderr, "run %d differs from run 0 with the same seed:\n%s%s", k, first.c_str(), text.c_str());
      return 1;
    }
  }
  std::printf("%s, %.0f s at %.0f kHz, seed %llu, %d runs (one thread):\n", scene_file ? scene_file : "base case",
              duration, scene.fs / 1e3,
              static_cast<unsigned long long>(seed), repeat);
  for (const auto* s : {&synth, &process, &total}) show(*s);
  std::printf("  first run  %.3f s; freed memory %s\n", total.seconds.front(),
              kept ? "kept for the next run" : "returned (glibc's defaults)");
  awcc::Sha256 hash;
  hash.update({reinterpret_cast<const std::uint8_t*>(first.data()), first.size()});
  std::printf("results:\n%sfingerprint %s\n", first.c_str(), hash.hex().substr(0, 16).c_str());
  std::printf("peak memory %.0f MB\n", bench::peak_mb());
  return 0;
}
