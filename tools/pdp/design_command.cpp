#include "design_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <set>

#include "awcc/atomic_output.hpp"
#include "awcc/errors.hpp"
#include "awcc/parallel.hpp"
#include "awcc/version.hpp"
#include "correction/features.hpp"
#include "correction/model.hpp"
#include "report_command.hpp"
#include "study/clock.hpp"
#include "study/design.hpp"
#include "sweep_engine.hpp"

namespace pdp {

void setup_design(CLI::App& app, Command& command, DesignOptions& o) {
  auto* cmd = app.add_subcommand("design",
                                 "Rank probe geometries and settings (dx, dy, Np, fs, record length) for a flow by "
                                 "simulating it: errors of u and Tu, raw and corrected, yield and cost");
  command.app = cmd;
  // --config is the design itself (conditions and candidates), not a file
  // of this command's options: its [design] table holds the model.
  command.required.push_back(
      cmd->add_option("--config", o.config,
                      "the design (TOML): [conditions.NAME] flows, [candidates], optional [current] probe and "
                      "[design] settings (docs/design.md)")
          ->check(CLI::ExistingFile));
  command.required.push_back(
      path_option(cmd->add_option("-o,--output", o.output, "ranked CSV: one row per candidate and condition")));
  path_option(cmd->add_option("--report", o.report, "HTML page: error maps over (dx, dy) per condition, the ranking"));
  path_option(cmd->add_option("--model", o.model,
                              "correction model (.qrf, e.g. samples/model/awcc.qrf); without one, raw AWCC is ranked"))
      ->check(CLI::ExistingFile);
  cmd->add_option("--runs", o.runs,
                  "runs CSVs (every record's results; an interrupted design resumes from them; shards give one each, "
                  "then all together) [default: OUTPUT.runs.csv]");
  cmd->add_option("--threads", o.threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 4096))->capture_default_str();
  cmd->add_option("--shard", o.shard, "i/n: simulate only the records whose task index is i modulo n");
}

namespace {

std::string runs_default(const std::string& output) {
  std::filesystem::path p(output);
  return (p.parent_path() / (p.stem().string() + ".runs.csv")).string();
}

}  // namespace

int run_design(const DesignOptions& o) {
  const MpiSession mpi;
  study::DesignDefinition d;
  std::int64_t shard = 0, shards = 1;
  std::optional<correction::CorrectionModel> model;
  std::string model_note;
  const awcc::AwccOptions processing;  // AWCC as pdp process runs it by default
  try {
    d = study::load_design(o.config);
    if (!o.shard.empty()) std::tie(shard, shards) = parse_shard(o.shard);
    std::string model_path = o.model;
    if (model_path.empty() && !d.model.empty()) {
      // A relative path in the design file is relative to the file.
      const std::filesystem::path p(d.model);
      model_path = (p.is_absolute() ? p : std::filesystem::path(o.config).parent_path() / p).string();
    }
    if (!model_path.empty()) {
      model = correction::CorrectionModel::load(model_path);
      if (const auto why = model->mismatch(correction::processing_of(processing)); !why.empty()) {
        throw awcc::InputError(fmt::format("{}: the model learnt another AWCC processing ({}); pdp design runs AWCC "
                                           "with its defaults: give a model trained on them",
                                           model_path, why));
      }
      model_note = "corrected by " + std::filesystem::path(model_path).filename().string();
    } else if (d.values == "corrected") {
      spdlog::warn("no correction model (--model or [design] model): the ranking is of raw AWCC");
      d.values = "raw";
      model_note = "no correction model given: raw AWCC";
    } else {
      model_note = "raw AWCC";
    }
  } catch (const awcc::InputError& e) {
    return report_error(e);
  } catch (const std::exception& e) {
    const int code = report_error(e);
    return code == exit_bad_input ? exit_bad_usage : code;
  }
  // Every record's scene before any is simulated: a flow the simulator
  // cannot make is the design's fault, named before minutes are spent.
  for (std::int64_t t = 0; t < d.tasks(); ++t) {
    const auto task = d.task(t);
    if (const auto validation = task.scene.validate(); !validation.ok()) {
      spdlog::error("{}: condition {} record {}: {}", o.config, d.conditions[task.condition].name, task.record,
                    one_line(validation.message));
      return exit_bad_usage;
    }
  }
  const std::uint64_t id = study::design_id(d);
  const std::vector<std::string> runs = o.runs.empty() ? std::vector<std::string>{runs_default(o.output)} : o.runs;
  std::set<std::int64_t> done;
  int refused = 0;
  if (mpi.rank() == 0) {
    try {
      awcc::check_output_folder(o.output);
      if (!o.report.empty()) awcc::check_output_folder(o.report);
      const auto resumed = study::resume_design(d, {runs.begin(), runs.end()}, id);
      done = resumed.done;
      if (resumed.cut_short > 0) {
        spdlog::warn("{}: {} records were cut short by an interruption; they run again", runs.front(), resumed.cut_short);
      }
    } catch (const std::exception& e) {
      refused = report_error(e);
    }
  }
  mpi.share(refused, done);
  if (refused) return refused;
  std::vector<std::int64_t> pending;
  for (std::int64_t t = 0; t < d.tasks(); ++t) {
    if (t % shards == shard && !done.count(t)) pending.push_back(t);
  }
  const correction::CorrectionModel* m = model ? &*model : nullptr;
  if (mpi.rank() == 0) {
    spdlog::info("{}: {} conditions x {} candidates: {} records to simulate ({} in {}), each processed at {} probe "
                 "geometries x {} Np",
                 o.config, d.conditions.size(), d.candidates().size(), d.tasks(), done.size(), runs.front(),
                 d.geometries.size(), d.nps.size());
    if (!pending.empty()) {
      constexpr double pilot_seconds = 2.0;
      const double total = study::estimate_design_seconds(d, pending, m, processing, pilot_seconds);
      const double workers = mpi.on() && mpi.size() > 1 ? mpi.size() - 1 : awcc::thread_count(o.threads, pending.size());
      const double estimate = total / workers;
      spdlog::info("about {} on {} {} (from a {:g} s pilot of each condition)",
                   estimate < 90 ? fmt::format("{:.0f} s", estimate) : fmt::format("{:.1f} minutes", estimate / 60.0),
                   workers, mpi.on() && mpi.size() > 1 ? "ranks" : "threads", pilot_seconds);
    }
  }
  auto compute = [&](std::int64_t t) {
    const auto task = d.task(t);
    std::string text;
    try {
      for (const auto& r : study::run_design_task(d, task, m, processing)) text += study::design_row_text(r, id) + "\n";
    } catch (const std::exception& e) {
      // A record that cannot be simulated is the design's fault: say which.
      throw awcc::InputError(fmt::format("{}: condition {} record {}: {}", o.config, d.conditions[task.condition].name,
                                         task.record, e.what()));
    }
    return text;
  };
  if (const int status = run_tasks(pending, compute, runs.front(), o.threads, "designing", mpi); status != exit_ok) {
    return status;
  }
  if (mpi.rank() != 0) return exit_ok;
  try {
    std::vector<study::DesignRow> rows;
    for (const auto& file : runs) {
      auto more = study::read_design_rows(file, id);
      rows.insert(rows.end(), more.begin(), more.end());
    }
    std::set<std::int64_t> tasks_present;
    for (const auto& r : rows) tasks_present.insert(r.task);
    if (static_cast<std::int64_t>(tasks_present.size()) < d.tasks()) {
      spdlog::info("{} of {} records simulated: rank them once every shard has run, with all the runs files "
                   "(--runs FILE --runs FILE ...)",
                   tasks_present.size(), d.tasks());
      return exit_ok;
    }
    const auto ranked = study::rank_candidates(d, rows);
    awcc::write_text_atomically(o.output, study::ranked_csv(ranked, d));
    fmt::print("{}", study::design_summary(ranked, d, model_note));
    spdlog::info("{}: {} candidates ranked", o.output, ranked.size());
    if (!o.report.empty()) {
      return write_report({o.output, "--config", o.config, "-o", o.report, "--pdp-version", awcc::version},
                          "design_report.py");
    }
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
