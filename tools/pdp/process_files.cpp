#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "awcc/errors.hpp"
#include "hints.hpp"
#include "process_steps.hpp"
#include "synth/sidecar.hpp"
#include "terminal.hpp"

namespace pdp {

namespace {

// The row's one list (awcc/assess.hpp), as the JSON and CSV write it.
void warn_about(const std::string& file, const awcc::ProcessResult& r) {
  for (const auto& w : r.warnings) spdlog::warn("{}: {} [{}]", file, w.text, awcc::to_string(w.flag));
}

}  // namespace

Processed process_files(const ProcessCommandOptions& o, const Plan& plan) {
  Processed out;
  Progress progress("processing");
  awcc::ProcessWorkspace workspace;  // FFT plans shared by the records
  for (std::size_t i = 0; i < o.files.size(); ++i) {
    // A synthetic recording's sidecar states its volts per count.
    awcc::ProcessOptions file_options = plan.options;
    // The JSON (or the report made from it) records each input's SHA-256: hashed as the file is read.
    file_options.hash_input = !o.json.empty() || !o.report.empty();
    if (!(file_options.reader.volts_per_count > 0.0)) {
      if (const auto vpc = synth::sidecar_volts_per_count(o.files[i])) file_options.reader.volts_per_count = *vpc;
    }
    try {
      out.results.push_back(awcc::process_recording(o.files[i], file_options, workspace));
    } catch (const awcc::InputError& e) {
      // Among several inputs (a glob), a file that is not a recording is
      // skipped and said; a damaged recording still stops the profile.
      if (o.files.size() == 1 || e.quantity() != "not_a_recording") throw;
      spdlog::warn("skipped: {}", e.what());
      out.skipped.push_back(e.what());
      continue;
    }
    add_flag_hints(out.results.back());
    if (!o.manifest.empty() && !plan.positions[i]) {
      const auto name = std::filesystem::path(o.files[i]).filename().string();
      throw std::invalid_argument(
          fmt::format("{}: no position for {}; add a row '{},<position>'", o.manifest, name, name));
    }
    out.positions.push_back(plan.positions[i]);
    out.inputs.push_back(o.files[i]);
    warn_about(o.files[i], out.results.back());
    spdlog::debug("{}: {:.3f} s", o.files[i], out.results.back().seconds);
    progress(static_cast<double>(i + 1) / static_cast<double>(o.files.size()));
  }
  if (out.results.empty()) {
    throw awcc::InputError(fmt::format("none of the {} inputs is a recording", o.files.size()));
  }
  return out;
}

std::vector<correction::Correction> corrections_of(const Plan& plan, const Processed& p) {
  std::vector<correction::Correction> corrections;
  if (!plan.model) return corrections;
  for (const auto& r : p.results) {
    corrections.push_back(plan.model->correct(correction::measurement_of(r)));
    const auto& c = corrections.back();
    if (!c.corrected()) spdlog::warn("{}: not corrected: {}", r.info.path.string(), c.why_not());
    for (const auto& n : c.notes) spdlog::warn("{}: {}", r.info.path.string(), n);
    if (c.large_bubbles) spdlog::warn("{}: {}", r.info.path.string(), c.turbulence_message);
  }
  return corrections;
}

}  // namespace pdp
