#include "sweep_engine.hpp"

#include <cstdlib>
#include <spdlog/spdlog.h>
#include <stdexcept>

#include "awcc/units.hpp"
#include "command.hpp"
#include "study/tasks.hpp"
#include "terminal.hpp"

#ifdef PDP_WITH_MPI
#include <mpi.h>
#endif

namespace pdp {

MpiSession::MpiSession() {
#ifdef PDP_WITH_MPI
  on_ = std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr;
  if (on_) {
    MPI_Init(nullptr, nullptr);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
#endif
}

MpiSession::~MpiSession() {
#ifdef PDP_WITH_MPI
  if (on_) MPI_Finalize();
#endif
}

void MpiSession::share([[maybe_unused]] int& code, [[maybe_unused]] std::set<std::int64_t>& done) const {
#ifdef PDP_WITH_MPI
  if (!on_) return;
  MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::vector<std::int64_t> list(done.begin(), done.end());
  std::int64_t count = static_cast<std::int64_t>(list.size());
  MPI_Bcast(&count, 1, MPI_INT64_T, 0, MPI_COMM_WORLD);
  list.resize(static_cast<std::size_t>(count));
  MPI_Bcast(list.data(), static_cast<int>(count), MPI_INT64_T, 0, MPI_COMM_WORLD);
  done = std::set<std::int64_t>(list.begin(), list.end());
#endif
}

std::pair<std::int64_t, std::int64_t> parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) throw std::invalid_argument("--shard: write i/n, e.g. 3/10");
  const auto shard = awcc::parse_whole(text.substr(0, slash), 0, std::int64_t{1} << 40);
  const auto shards = awcc::parse_whole(text.substr(slash + 1), 1, std::int64_t{1} << 40);
  if (shards < 1 || shard < 0 || shard >= shards) throw std::invalid_argument("--shard i/n needs 0 <= i < n");
  return {shard, shards};
}

namespace {

#ifdef PDP_WITH_MPI
// Rank 0 is the one writer and hands out tasks one at a time; the other
// ranks compute them and send their text back. Every rank reads the same
// study, so a task index is all a message needs.
void run_over_ranks(const std::vector<std::int64_t>& tasks, const std::function<std::string(std::int64_t)>& compute,
                    const std::string& output, const std::string& label, const MpiSession& mpi) {
  constexpr int kText = 1, kTask = 2;
  if (mpi.rank() == 0) {
    study::AppendFile file(output);
    std::size_t next = 0, written = 0;
    int active = mpi.size() - 1;
    Progress progress(label);
    while (active > 0) {
      MPI_Status status;
      MPI_Probe(MPI_ANY_SOURCE, kText, MPI_COMM_WORLD, &status);
      int length = 0;
      MPI_Get_count(&status, MPI_CHAR, &length);
      std::string text(static_cast<std::size_t>(length), '\0');
      MPI_Recv(text.data(), length, MPI_CHAR, status.MPI_SOURCE, kText, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (!text.empty()) {
        file.append(text);
        progress(static_cast<double>(++written) / static_cast<double>(tasks.size()));
      }
      std::int64_t task = next < tasks.size() ? static_cast<std::int64_t>(next++) : -1;
      if (task < 0) --active;
      MPI_Send(&task, 1, MPI_INT64_T, status.MPI_SOURCE, kTask, MPI_COMM_WORLD);
    }
    spdlog::info("{}: {} tasks written by {} ranks", output, written, mpi.size() - 1);
  } else {
    std::string text;  // empty: "ready"
    for (;;) {
      MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, 0, kText, MPI_COMM_WORLD);
      std::int64_t task = -1;
      MPI_Recv(&task, 1, MPI_INT64_T, 0, kTask, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (task < 0) break;
      text = compute(tasks[static_cast<std::size_t>(task)]);
    }
  }
}
#endif

}  // namespace

int run_tasks(const std::vector<std::int64_t>& tasks, const std::function<std::string(std::int64_t)>& compute,
              const std::string& output, int threads, const std::string& label, const MpiSession& mpi) {
  try {
#ifdef PDP_WITH_MPI
    if (mpi.on() && mpi.size() > 1) {
      run_over_ranks(tasks, compute, output, label, mpi);
      return exit_ok;
    }
#endif
    (void)mpi;
    Progress progress(label);
    study::run_tasks(tasks, compute, output, threads, [&](double fraction) { progress(fraction); });
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return exit_ok;
}

}  // namespace pdp
