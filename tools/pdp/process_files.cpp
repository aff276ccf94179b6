#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "awcc/errors.hpp"
#include "awcc/memory.hpp"
#include "hints.hpp"
#include "process_steps.hpp"
#include "terminal.hpp"

namespace pdp {

namespace {

// The row's one list (awcc/assess.hpp), as the JSON and CSV write it.
void warn_about(const std::string& file, const awcc::ProcessResult& r) {
  for (const auto& w : r.warnings) spdlog::warn("{}: {} [{}]", file, w.text, awcc::to_string(w.flag));
}

}  // namespace

study::ProfileRun process_files(const ProcessCommandOptions& o, const Plan& plan) {
  Progress progress("processing");
  study::ProfileRunOptions options;
  options.processing = plan.options;
  options.flow = plan.flow;
  options.model = plan.model ? &*plan.model : nullptr;
  // The JSON (or the report made from it) records each input's SHA-256: hashed as the file is read.
  options.hash_inputs = !o.json.empty() || !o.report.empty() || !o.mat.path.empty();
  options.manifest = o.manifest;
  options.on_result = [](awcc::ProcessResult& r) { add_flag_hints(r); };
  options.progress = [&progress](double f) { progress(f); };
  // Several recordings run one after another on each thread, as scenes do
  // in a sweep: keep the freed blocks instead of faulting the same pages in
  // again for each (docs/performance.md, "Freed memory kept only where
  // scenes repeat").
  if (o.files.size() > 1) awcc::keep_freed_memory();
  auto run = study::process_profile(o.files, plan.positions, options);
  for (const auto& s : run.skipped) spdlog::warn("skipped: {}", s);
  for (std::size_t i = 0; i < run.results.size(); ++i) {
    warn_about(run.inputs[i], run.results[i]);
    spdlog::debug("{}: {:.3f} s", run.inputs[i], run.results[i].seconds);
  }
  for (const auto& w : run.warnings()) spdlog::warn("{}", w);
  return run;
}

}  // namespace pdp
