#include "sweep_command.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fmt/format.h>
#include <mutex>
#include <spdlog/spdlog.h>
#include <thread>

#include "awcc/atomic_output.hpp"
#include "awcc/errors.hpp"
#include "awcc/parallel.hpp"
#include "awcc/units.hpp"
#include "sweep.hpp"
#include "terminal.hpp"

#ifdef PDP_WITH_MPI
#include <mpi.h>
#endif

namespace pdp {

void setup_sweep(CLI::App& app, Command& command, SweepOptions& o) {
  auto* cmd = app.add_subcommand("sweep", "Run a grid or Monte Carlo study of synthetic scenes into a CSV");
  command.app = cmd;
  add_config_option(command);
  command.required.push_back(
      cmd->add_option("study", o.study, "sweep definition (TOML: [sweep], [base], [grid], [ranges])")
          ->check(CLI::ExistingFile));
  command.required.push_back(
      cmd->add_option("-o,--output", o.output, "CSV of runs: appended row by row; an interrupted sweep resumes"));
  cmd->add_option("--threads", o.threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 4096))
      ->capture_default_str();
  cmd->add_option("--shard", o.shard, "i/n: run only the runs whose index is i modulo n (cluster job arrays)");
  add_method_options(cmd, o.methods);
}

namespace {

void write_all(int fd, const std::string& text, const std::string& path) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw awcc::OutputError(fmt::format("{}: write failed: {}", path, std::strerror(errno)));
    }
    done += static_cast<std::size_t>(n);
  }
}

#ifdef PDP_WITH_MPI
// Under mpirun: rank 0 is the one writer and hands out runs one at a time;
// the other ranks compute them and send their rows back. Every rank reads
// the same study, so a run index is all a message needs.
int mpi_size() {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

template <class Compute>
int sweep_over_ranks(const std::vector<const SweepRun*>& pending, Compute&& compute_row, int fd,
                     const std::string& output) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  constexpr int kRow = 1, kTask = 2;
  if (rank == 0) {
    std::size_t next = 0, written = 0;
    int active = size - 1;
    Progress progress("sweeping");
    while (active > 0) {
      MPI_Status status;
      MPI_Probe(MPI_ANY_SOURCE, kRow, MPI_COMM_WORLD, &status);
      int length = 0;
      MPI_Get_count(&status, MPI_CHAR, &length);
      std::string row(static_cast<std::size_t>(length), '\0');
      MPI_Recv(row.data(), length, MPI_CHAR, status.MPI_SOURCE, kRow, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (!row.empty()) {
        write_all(fd, row + "\n", output);
        ::fdatasync(fd);
        progress(static_cast<double>(++written) / static_cast<double>(pending.size()));
      }
      std::int64_t task = next < pending.size() ? static_cast<std::int64_t>(next++) : -1;
      if (task < 0) --active;
      MPI_Send(&task, 1, MPI_INT64_T, status.MPI_SOURCE, kTask, MPI_COMM_WORLD);
    }
    spdlog::info("{}: {} runs written by {} ranks", output, written, size - 1);
  } else {
    std::string row;  // empty: "ready"
    for (;;) {
      MPI_Send(row.data(), static_cast<int>(row.size()), MPI_CHAR, 0, kRow, MPI_COMM_WORLD);
      std::int64_t task = -1;
      MPI_Recv(&task, 1, MPI_INT64_T, 0, kTask, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (task < 0) break;
      row = compute_row(*pending[static_cast<std::size_t>(task)]);
    }
  }
  return 0;
}
#endif

}  // namespace

int run_sweep(const SweepOptions& o) {
#ifdef PDP_WITH_MPI
  // MPI only when started by mpirun, so that a plain run needs no MPI daemon.
  struct MpiSession {
    bool on = std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr;
    MpiSession() {
      if (on) MPI_Init(nullptr, nullptr);
    }
    ~MpiSession() {
      if (on) MPI_Finalize();
    }
  } mpi;
  int rank = 0;
  if (mpi.on) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
#else
  const int rank = 0;
#endif
  SweepDefinition definition;
  std::vector<SweepRun> runs;
  StudyOptions study;
  std::int64_t shard = 0, shards = 1;
  try {
    definition = load_sweep(o.study);
    runs = definition.expand();
    apply_method_options(o.methods, study);
    // A method option of the command line applies to every run, unless the
    // study sets it: then the two conflict.
    if (o.methods.given("np")) {
      if (sets(definition, "np")) {
        throw std::invalid_argument(fmt::format("--np {} conflicts with np set in {}; give it in one place",
                                                study.awcc.np, o.study));
      }
      for (auto& run : runs) run.np = study.awcc.np;
    }
    if (!o.shard.empty()) {
      const auto slash = o.shard.find('/');
      if (slash == std::string::npos) throw std::invalid_argument("--shard: write i/n, e.g. 3/10");
      shard = awcc::parse_whole(o.shard.substr(0, slash), 0, std::int64_t{1} << 40);
      shards = awcc::parse_whole(o.shard.substr(slash + 1), 1, std::int64_t{1} << 40);
      if (shards < 1 || shard < 0 || shard >= shards) throw std::invalid_argument("--shard i/n needs 0 <= i < n");
    }
  } catch (const std::exception& e) {
    // A sweep file that cannot be used is a usage error, as an option is.
    const int code = report_error(e);
    return code == exit_bad_input ? exit_bad_usage : code;
  }
  for (const auto& run : runs) {
    if (const auto errors = run.scene.validate(); !errors.empty()) {
      spdlog::error("{}: run {} has an invalid scene: {}", o.study, run.index, errors.front());
      return exit_bad_usage;
    }
  }
  const std::uint64_t id = study_id(definition);
  std::set<std::int64_t> done;
  int refused = 0;
  if (rank == 0) {
    try {
      done = finished_runs(o.output, id);
      std::error_code ec;
      if (!std::filesystem::exists(o.output, ec) || std::filesystem::file_size(o.output, ec) == 0) {
        awcc::write_text_atomically(o.output, sweep_header() + "\n");
      }
    } catch (const std::exception& e) {
      refused = report_error(e);
    }
  }
#ifdef PDP_WITH_MPI
  if (mpi.on) {
    // The writer's view of finished runs, to every rank.
    MPI_Bcast(&refused, 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<std::int64_t> list(done.begin(), done.end());
    std::int64_t count = static_cast<std::int64_t>(list.size());
    MPI_Bcast(&count, 1, MPI_INT64_T, 0, MPI_COMM_WORLD);
    list.resize(static_cast<std::size_t>(count));
    MPI_Bcast(list.data(), static_cast<int>(count), MPI_INT64_T, 0, MPI_COMM_WORLD);
    done = std::set<std::int64_t>(list.begin(), list.end());
  }
#endif
  if (refused) return refused;
  std::vector<const SweepRun*> pending;
  for (const auto& run : runs) {
    if (run.index % shards != shard || done.count(run.index)) continue;
    pending.push_back(&run);
  }
  if (rank == 0) {
    spdlog::info("{}: {} runs in the study, {} already in {}, {} to run{}", o.study, runs.size(), done.size(),
                 o.output, pending.size(), shards > 1 ? fmt::format(" (shard {}/{})", shard, shards) : "");
  }
  const int fd = rank == 0 ? ::open(o.output.c_str(), O_WRONLY | O_APPEND) : -1;
  if (rank == 0 && fd < 0) {
    spdlog::error("{}: cannot open for appending: {}", o.output, std::strerror(errno));
    return exit_output_failed;
  }
  auto compute_row = [&](const SweepRun& run) {
    StudyOptions options = study;
    options.awcc.np = run.np;
    try {
      const RunResult r = run_scene(run.scene, options);
      return sweep_row(run, &r, "", id, options.awcc);
    } catch (const std::exception& e) {
      return sweep_row(run, nullptr, e.what(), id, options.awcc);
    }
  };
#ifdef PDP_WITH_MPI
  if (mpi.on && mpi_size() > 1) {
    const int status = sweep_over_ranks(pending, compute_row, fd, o.output);
    if (fd >= 0) ::close(fd);
    return status;
  }
#endif
  std::atomic<std::size_t> finished{0};
  std::mutex write_mutex;
  try {
    Progress progress("sweeping");
    awcc::parallel_for(pending.size(), o.threads, [&](std::size_t i) {
      const std::string row = compute_row(*pending[i]);
      std::lock_guard lock(write_mutex);
      // One write per row, then to disk: a crash loses no finished row. A
      // failed write stops the sweep (the pool hands out no further run).
      write_all(fd, row + "\n", o.output);
      ::fdatasync(fd);
      progress(static_cast<double>(++finished) / static_cast<double>(pending.size()));
    });
  } catch (const std::exception& e) {
    ::close(fd);
    return report_error(e);
  }
  ::close(fd);
  spdlog::info("{}: {} runs written", o.output, finished.load());
  return exit_ok;
}

}  // namespace pdp
