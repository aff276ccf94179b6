#include "sweep_engine.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fmt/format.h>
#include <mutex>
#include <spdlog/spdlog.h>
#include <stdexcept>

#include "awcc/errors.hpp"
#include "awcc/parallel.hpp"
#include "awcc/units.hpp"
#include "command.hpp"
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
// Rank 0 is the one writer and hands out tasks one at a time; the other
// ranks compute them and send their text back. Every rank reads the same
// study, so a task index is all a message needs.
int run_over_ranks(const std::vector<std::int64_t>& tasks, const std::function<std::string(std::int64_t)>& compute,
                   int fd, const std::string& output, const std::string& label, const MpiSession& mpi) {
  constexpr int kText = 1, kTask = 2;
  if (mpi.rank() == 0) {
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
        write_all(fd, text, output);
        ::fdatasync(fd);
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
  return exit_ok;
}
#endif

}  // namespace

int run_tasks(const std::vector<std::int64_t>& tasks, const std::function<std::string(std::int64_t)>& compute,
              const std::string& output, int threads, const std::string& label, const MpiSession& mpi) {
  const int fd = mpi.rank() == 0 ? ::open(output.c_str(), O_WRONLY | O_APPEND) : -1;
  if (mpi.rank() == 0 && fd < 0) {
    spdlog::error("{}: cannot open for appending: {}", output, std::strerror(errno));
    return exit_output_failed;
  }
#ifdef PDP_WITH_MPI
  if (mpi.on() && mpi.size() > 1) {
    int status = exit_ok;
    try {
      status = run_over_ranks(tasks, compute, fd, output, label, mpi);
    } catch (const std::exception& e) {
      status = report_error(e);
    }
    if (fd >= 0) ::close(fd);
    return status;
  }
#endif
  std::atomic<std::size_t> finished{0};
  std::mutex write_mutex;
  try {
    Progress progress(label);
    awcc::parallel_for(tasks.size(), threads, [&](std::size_t i) {
      const std::string text = compute(tasks[i]);
      std::lock_guard lock(write_mutex);
      // One write per task, then to disk: a crash loses no finished task. A
      // failed write stops the study (the pool hands out no further task).
      write_all(fd, text, output);
      ::fdatasync(fd);
      progress(static_cast<double>(++finished) / static_cast<double>(tasks.size()));
    });
  } catch (const std::exception& e) {
    ::close(fd);
    return report_error(e);
  }
  ::close(fd);
  return exit_ok;
}

}  // namespace pdp
