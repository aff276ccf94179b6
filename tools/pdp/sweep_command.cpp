#include "sweep_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "awcc/atomic_output.hpp"
#include "study/sweep.hpp"
#include "sweep_engine.hpp"


namespace pdp {

void setup_sweep(CLI::App& app, Command& command, SweepOptions& o) {
  auto* cmd = app.add_subcommand("sweep", "Run a grid or Monte Carlo study of synthetic scenes into a CSV");
  command.app = cmd;
  add_config_option(command);
  command.required.push_back(
      path_option(cmd->add_option("study", o.study, "sweep definition (TOML: [sweep], [base], [grid], [ranges], [choices])"))
          ->check(CLI::ExistingFile));
  command.required.push_back(path_option(
      cmd->add_option("-o,--output", o.output, "CSV of runs: appended row by row; an interrupted sweep resumes")));
  cmd->add_option("--threads", o.threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 4096))
      ->capture_default_str();
  cmd->add_option("--shard", o.shard, "i/n: run only the runs whose index is i modulo n (cluster job arrays)");
  // A Monte Carlo sweep's first N runs are a random sample of it, and which
  // runs they are does not depend on when the sweep was stopped: a campaign
  // that needs only part of a sweep asks for it, and a later call with a
  // larger N (or without it) resumes the rest into the same file.
  cmd->add_option("--first-runs", o.first_runs,
                  "run only the runs whose index is below N (0 = every run); a later call resumes the rest")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40))
      ->capture_default_str();
  add_method_options(cmd, o.methods);
}

int run_sweep(const SweepOptions& o) {
  const MpiSession mpi;
  study::SweepDefinition definition;
  std::vector<study::SweepRun> runs;
  study::RunOptions options;
  std::int64_t shard = 0, shards = 1;
  try {
    definition = study::load_sweep(o.study);
    runs = definition.expand();
    apply_method_options(o.methods, options);
    // A method option of the command line applies to every run, unless the
    // study sets it: then the two conflict.
    if (o.methods.given("np")) {
      if (study::sets(definition, "np")) {
        throw std::invalid_argument(fmt::format("--np {} conflicts with np set in {}; give it in one place",
                                                options.awcc.np, o.study));
      }
      for (auto& run : runs) run.np = options.awcc.np;
    }
    if (!o.shard.empty()) std::tie(shard, shards) = parse_shard(o.shard);
  } catch (const std::exception& e) {
    // A sweep file that cannot be used is a usage error, as an option is.
    const int code = report_error(e);
    return code == exit_bad_input ? exit_bad_usage : code;
  }
  for (const auto& run : runs) {
    if (const auto validation = run.scene.validate(); !validation.ok()) {
      spdlog::error("{}: run {} has an invalid scene: {}", o.study, run.index, one_line(validation.message));
      return exit_bad_usage;
    }
  }
  const std::uint64_t id = study::study_id(definition);
  std::set<std::int64_t> done;
  int refused = 0;
  if (mpi.rank() == 0) {
    try {
      awcc::check_output_folder(o.output);  // a folder named as the output is said as such
      done = study::finished_runs(o.output, id);
      std::error_code ec;
      if (!std::filesystem::exists(o.output, ec) || std::filesystem::file_size(o.output, ec) == 0) {
        awcc::write_text_atomically(o.output, study::sweep_header() + "\n");
      }
    } catch (const std::exception& e) {
      refused = report_error(e);
    }
  }
  mpi.share(refused, done);
  if (refused) return refused;
  std::vector<std::int64_t> pending;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (runs[i].index % shards != shard || done.count(runs[i].index)) continue;
    if (o.first_runs > 0 && runs[i].index >= o.first_runs) continue;
    pending.push_back(static_cast<std::int64_t>(i));
  }
  if (mpi.rank() == 0) {
    spdlog::info("{}: {} runs in the study, {} already in {}, {} to run{}{}", o.study, runs.size(), done.size(),
                 o.output, pending.size(), shards > 1 ? fmt::format(" (shard {}/{})", shard, shards) : "",
                 o.first_runs > 0 ? fmt::format(" (runs below {})", o.first_runs) : "");
  }
  auto compute_row = [&](std::int64_t i) {
    return study::run_sweep_row(runs[static_cast<std::size_t>(i)], options, id);
  };
  const int status = run_tasks(pending, compute_row, o.output, o.threads, "sweeping", mpi);
  if (status == exit_ok && mpi.rank() == 0 && !(mpi.on() && mpi.size() > 1)) {
    spdlog::info("{}: {} runs written", o.output, pending.size());
  }
  return status;
}

}  // namespace pdp
