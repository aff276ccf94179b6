// Benchmark of Felder's analysis (issue 13, docs/performance.md): every
// output of `--preset felder` (raw-voltage FSCC in 15 segments with his lags
// and scales, voltage and chord PDFs, the cluster analyses on chord lengths
// and times, inter-particle arrivals) for recordings processed in turn on one
// thread, as `pdp process` does, without writing the outputs.
//
//   felder_bench FILE... [--fs HZ] [--dx M] [--repeat N]
//
// Prints the median and the fastest of N runs over all the files, and the
// peak memory of the process. Felder's program (gfortran -O0, the ten
// stepped-spillway files) takes 18.5 s.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "awcc/options.hpp"
#include "awcc/process.hpp"
#include "bench_util.hpp"

namespace {

// The preset through the options' own declarations, as the command line applies it.
template <class T>
void apply_preset(std::span<const awcc::OptionField<T>> fields, T& target) {
  for (const auto& f : fields)
    for (const auto& p : awcc::preset_settings("felder"))
      if (p.name == f.name) f.parse(target, p.value);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  awcc::ProcessOptions options;
  options.reader.fs = 20e3;
  options.dx = 7.15e-3;
  int repeat = 5;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--fs") && i + 1 < argc) options.reader.fs = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--dx") && i + 1 < argc) options.dx = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else files.emplace_back(argv[i]);
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: felder_bench FILE... [--fs HZ] [--dx M] [--repeat N]\n");
    return 2;
  }
  apply_preset(awcc::process_option_fields(), options);
  apply_preset(awcc::binarisation_option_fields(), options.binarisation);
  apply_preset(awcc::fscc_option_fields(), options.fscc_options);
  apply_preset(awcc::awcc_option_fields(), options.awcc_options);
  apply_preset(awcc::structure_option_fields(), options.structure);
  std::vector<double> times;
  std::size_t clusters = 0;
  awcc::ProcessWorkspace workspace;  // plans shared by the records, as pdp process shares them
  for (int r = 0; r < repeat; ++r) {
    const double t0 = bench::now();
    for (const auto& f : files) {
      const auto result = awcc::process_recording(f, options, workspace);
      clusters += result.structure->clusters_length.criteria.size();  // keep the work observable
    }
    times.push_back(bench::now() - t0);
  }
  std::printf("felder preset, %zu files: median %.3f s, fastest %.3f s over %d runs; peak memory %.1f MB (%zu)\n",
              files.size(), bench::median(times), *std::min_element(times.begin(), times.end()), repeat,
              bench::peak_mb(), clusters);
  return 0;
}
