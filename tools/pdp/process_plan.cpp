#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/options.hpp"
#include "awcc/sha256.hpp"
#include "awcc/units.hpp"
#include "process_steps.hpp"
#include "study/profile_run.hpp"

namespace pdp {

namespace {

awcc::ProcessOptions build_options(const ProcessCommandOptions& o) {
  auto settings = o.library.settings();
  if (!o.preset.empty()) settings.push_back({"preset", o.preset, origin_of("preset")});
  const auto p = awcc::process_options(settings);
  if (!o.windows.empty() && o.files.size() != 1) {
    throw std::invalid_argument("--windows writes the window table of one recording; give one file");
  }
  if (!o.windows.empty() && !p.awcc) throw std::invalid_argument("--windows needs --method awcc or both");
  if (!o.bubbles.empty() && o.files.size() != 1) {
    throw std::invalid_argument("--bubbles writes the bubble table of one recording; give one file");
  }
  if (!o.bubbles.empty() && !p.events && p.multi_tip == awcc::MultiTipChoice::off) {
    throw std::invalid_argument("--bubbles writes a per-bubble table: use --method events (a tip pair) or multi-tip "
                                "(a probe of four or more tips)");
  }
  if (!o.spectrum.empty() && (!p.awcc || !p.velocity_spectrum)) {
    throw std::invalid_argument("--spectrum writes AWCC's velocity spectrum: use --method awcc or both, and "
                                "--velocity-spectrum on");
  }
  if (!o.correlation_functions.empty() && !p.fscc) {
    throw std::invalid_argument("--correlation-functions writes FSCC's functions: use --method fscc or both");
  }
  return p;
}

// Positions per file: from --positions, or a manifest CSV "file,position"
// (study/profile_run.hpp reads both).
std::vector<std::optional<double>> positions_for(const ProcessCommandOptions& o) {
  if (!o.positions.empty() && !o.manifest.empty()) {
    throw std::invalid_argument("--positions and --manifest both give the positions; give one of them");
  }
  if (!o.positions.empty()) return study::positions_of_list(awcc::split_cells(o.positions), o.files, "--positions");
  if (!o.manifest.empty()) return study::positions_of_manifest(o.manifest, o.files);
  return std::vector<std::optional<double>>(o.files.size());
}

// Two outputs into one file would leave only the last; inputs are never
// modified, so an output that is one of them is refused.
void check_output_names(const ProcessCommandOptions& o) {
  const std::vector<std::pair<const char*, const std::string*>> named = {
      {"--json", &o.json},       {"--csv", &o.csv},
      {"--windows", &o.windows}, {"--bubbles", &o.bubbles}, {"--correlation-functions", &o.correlation_functions},
      {"--spectrum", &o.spectrum}, {"--report", &o.report}, {"--mat", &o.mat.path}};
  for (std::size_t a = 0; a < named.size(); ++a) {
    for (std::size_t b = a + 1; b < named.size(); ++b) {
      const auto& x = *named[a].second;
      const auto& y = *named[b].second;
      if (x.empty() || y.empty()) continue;
      std::error_code ec;
      if (x == y || (std::filesystem::exists(x) && std::filesystem::equivalent(x, y, ec))) {
        throw std::invalid_argument(fmt::format("{} and {} both name {}: give each output its own file",
                                                named[a].first, named[b].first, x));
      }
    }
  }
  for (const auto& output :
       {o.json, o.csv, o.windows, o.bubbles, o.correlation_functions, o.spectrum, o.report, o.mat.path}) {
    if (output.empty() || !std::filesystem::exists(output)) continue;
    for (const auto& input : o.files) {
      if (std::filesystem::equivalent(output, input)) {
        throw std::invalid_argument(fmt::format("{} is an input recording; choose another output file", output));
      }
    }
  }
}

// The first 64 KiB's digest: two recordings differ there (a copy does not),
// so whole files are compared only when their sizes and heads agree.
std::string head_digest(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> head(std::size_t{1} << 16);
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  awcc::Sha256 digest;
  digest.update({reinterpret_cast<const std::uint8_t*>(head.data()), static_cast<std::size_t>(in.gcount())});
  return digest.hex();
}

// A profile measures each position once: a file given twice (the same path,
// two paths to one file, or a copy under another name) would count one
// recording at two positions, and is refused naming both arguments.
void check_repeated_inputs(const std::vector<std::string>& files) {
  namespace fs = std::filesystem;
  std::map<std::pair<std::uintmax_t, std::string>, std::vector<std::size_t>> seen;  // (size, head digest) -> files
  std::map<std::size_t, std::string> whole;                                         // file -> digest of all its bytes
  auto whole_digest = [&](std::size_t i) -> const std::string& {
    auto it = whole.find(i);
    if (it == whole.end()) it = whole.emplace(i, awcc::sha256_of_file(files[i])).first;
    return it->second;
  };
  for (std::size_t j = 0; j < files.size(); ++j) {
    std::error_code ec;
    if (!fs::is_regular_file(files[j], ec)) continue;  // folders and README.md: skipped later, said there
    for (std::size_t i = 0; i < j; ++i) {
      if (files[i] == files[j] || fs::equivalent(files[i], files[j], ec)) {
        throw std::invalid_argument(
            fmt::format("{} and {} (files {} and {}) are one file: a profile measures each "
                        "position once; remove the repeat",
                        files[i], files[j], i + 1, j + 1));
      }
    }
    const auto size = fs::file_size(files[j], ec);
    if (ec) continue;
    auto& alike = seen[{size, head_digest(files[j])}];
    for (const std::size_t i : alike) {
      if (whole_digest(i) != whole_digest(j)) continue;
      throw std::invalid_argument(
          fmt::format("{} and {} (files {} and {}) hold the same bytes: one recording copied "
                      "under two names, not two measurements; give each position its own "
                      "recording",
                      files[i], files[j], i + 1, j + 1));
    }
    alike.push_back(j);
  }
}

}  // namespace

Plan plan_of(const ProcessCommandOptions& o) {
  Plan plan;
  check_repeated_inputs(o.files);
  plan.options = build_options(o);
  plan.positions = positions_for(o);
  if (!o.correct.empty() && !plan.options.awcc) {
    throw std::invalid_argument("--correct corrects AWCC's estimates; use --method awcc or both");
  }
  if (!o.correct.empty() && plan.options.awcc_options.probe_correction.enabled) {
    throw std::invalid_argument("--correct and --probe-correction both correct AWCC's velocity: the model was trained "
                                "on synthetic records without bubble-probe interaction; use one of them");
  }
  plan.flow = awcc::profile_flow_options(o.flow.settings());
  if (!o.flow.settings().empty()) {
    const bool positioned = std::all_of(plan.positions.begin(), plan.positions.end(),
                                        [](const std::optional<double>& p) { return p.has_value(); });
    if (o.files.size() < 2 || !positioned) {
      throw awcc::OptionError(fmt::format("--{}: a profile's flow quantities need two or more recordings with their "
                                          "positions (--positions or --manifest)",
                                          o.flow.settings().front().name),
                              o.flow.settings().front().name);
    }
  }
  check_output_names(o);
  // The model is read before any processing: a damaged one, or one trained
  // on other processing, fails fast.
  if (!o.correct.empty()) {
    plan.model = correction::CorrectionModel::load(o.correct);
    if (const auto why = plan.model->mismatch(correction::processing_of(plan.options.awcc_options)); !why.empty()) {
      throw std::invalid_argument(fmt::format("--correct {}: the model was trained on results processed otherwise "
                                              "({}); process with the model's settings or train a model for these",
                                              o.correct, why));
    }
  }
  return plan;
}

}  // namespace pdp
