// Benchmark of reading and binarising recordings (docs/performance.md).
//
//   process_bench FILE [--fs HZ] [--repeat N] [--fscc] [--block FRAMES] [--read-only] [--cold]
//
// Times, on one thread, (a) reading the whole file through libawcc's reader
// and nothing else (as volts, and as int16 counts where the file has them),
// (b) binarising both tips from the file, (c) that plus the tips' phase,
// chord and structure statistics (no correlation), and optionally (d) FSCC on
// the binarised signals. Prints the median of N
// runs, the samples per second and the peak memory of the process. With
// --read-only, (a) alone: the floor a whole run is compared with. With
// --cold, the file is dropped from the page cache before every timed read
// (bench::evict), so each read comes from the disk: a lab's first pass over
// a recording, where the page cache holds none of it.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "awcc/process.hpp"
#include "bench_util.hpp"

using bench::now;
using bench::peak_mb;
using bench::median;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: process_bench FILE [--fs HZ] [--repeat N] [--fscc] [--block FRAMES] [--read-only] [--cold]\n");
    return 2;
  }
  awcc::ProcessOptions options;
  int repeat = 3;
  bool with_fscc = false, read_only = false, cold = false;
  for (int i = 2; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--fs") && i + 1 < argc) options.reader.fs = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--fscc")) with_fscc = true;
    else if (!std::strcmp(argv[i], "--read-only")) read_only = true;
    else if (!std::strcmp(argv[i], "--cold")) cold = true;
    else if (!std::strcmp(argv[i], "--block") && i + 1 < argc) options.block_frames = std::atoll(argv[++i]);
  }
  options.dx = 5e-3;
  options.fscc = false;
  options.awcc = false;  // reading, binarising and the tips' statistics only
  std::vector<double> read_times, read16_times, binarise_times, process_times, fscc_times;
  std::int64_t frames = 0;
  int channels = 0;
  for (int r = 0; r < repeat; ++r) {
    {
      if (cold) bench::evict(argv[1]);
      const double t0 = now();
      auto rec = awcc::open_recording(argv[1], options.reader);
      channels = rec->info().channels;
      std::vector<float> block(static_cast<std::size_t>(options.block_frames * channels));
      frames = 0;
      double checksum = 0;
      for (;;) {
        const auto n = rec->read(block, options.block_frames);
        if (n == 0) break;
        frames += n;
        checksum += block[0];
      }
      read_times.push_back(now() - t0);
      if (rec->has_int16()) {
        if (cold) bench::evict(argv[1]);
        const double t1 = now();
        auto again = awcc::open_recording(argv[1], options.reader);
        std::vector<std::int16_t> counts(static_cast<std::size_t>(options.block_frames * channels));
        for (;;) {
          const auto n = again->read_int16(counts, options.block_frames);
          if (n == 0) break;
          checksum += counts[0];
        }
        read16_times.push_back(now() - t1);
      }
      if (checksum == 12345.678) std::puts("");  // keep the loop
    }
    if (read_only) continue;
    {
      if (cold) bench::evict(argv[1]);
      const double t0 = now();
      const auto binarised = awcc::binarise_recording(argv[1], options);
      binarise_times.push_back(now() - t0);
      const auto result = awcc::process_binarised(binarised, options);
      process_times.push_back(now() - t0);
      if (with_fscc) {
        const double t1 = now();
        awcc::fscc(binarised.leading, binarised.trailing, options.dx, {});
        fscc_times.push_back(now() - t1);
      }
      if (r == 0) {
        std::printf("c = %.5f / %.5f, F = %.2f / %.2f 1/s\n", result.tips[0].phase.void_fraction,
                    result.tips[1].phase.void_fraction, result.tips[0].phase.bubble_count_rate,
                    result.tips[1].phase.bubble_count_rate);
      }
    }
  }
  const double samples = static_cast<double>(frames) * channels;
  const double t_read = median(read_times);
  std::printf("%s: %lld frames x %d channels%s\n", argv[1], static_cast<long long>(frames), channels,
              cold ? " (each read from the disk: --cold)" : "");
  std::printf("read only (float volts):   %.3f s  (%.0f M samples/s)\n", t_read, samples / t_read / 1e6);
  if (!read16_times.empty()) {
    const double t16 = median(read16_times);
    std::printf("read only (int16 counts):  %.3f s  (%.0f M samples/s)\n", t16, samples / t16 / 1e6);
    if (!read_only) {
      std::printf("binarising (both tips, from the file) / int16 read: %.3f s, %.2f x\n", median(binarise_times),
                  median(binarise_times) / t16);
    }
  }
  if (read_only) {
    std::printf("peak memory %.0f MB (median of %d runs)\n", peak_mb(), repeat);
    return 0;
  }
  const double t_proc = median(process_times);
  std::printf("read + binarise + stats:   %.3f s  (%.0f M samples/s), %.2f x the read-only time\n", t_proc,
              samples / t_proc / 1e6, t_proc / t_read);
  if (with_fscc) std::printf("FSCC (full record, +/-20 ms): %.3f s\n", median(fscc_times));
  std::printf("peak memory %.0f MB (median of %d runs)\n", peak_mb(), repeat);
  return 0;
}
