#include "sweep_command.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fmt/format.h>
#include <mutex>
#include <spdlog/spdlog.h>
#include <thread>

#include "awcc/atomic_output.hpp"
#include "sweep.hpp"
#include "terminal.hpp"

namespace pdp {

CLI::App* setup_sweep(CLI::App& app, SweepOptions& o) {
  auto* cmd = app.add_subcommand("sweep", "Run a grid or Monte Carlo study of synthetic scenes into a CSV");
  cmd->add_option("study", o.study, "sweep definition (TOML: [sweep], [base], [grid], [ranges])")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o.output, "CSV of runs: appended row by row; an interrupted sweep resumes")->required();
  cmd->add_option("--threads", o.threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 4096))
      ->capture_default_str();
  cmd->add_option("--shard", o.shard, "i/n: run only the runs whose index is i modulo n (cluster job arrays)");
  add_method_options(cmd, o.methods);
  return cmd;
}

namespace {

void write_all(int fd, const std::string& text, const std::string& path) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(fmt::format("{}: write failed: {}", path, std::strerror(errno)));
    }
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace

int run_sweep(const SweepOptions& o) {
  SweepDefinition definition;
  std::vector<SweepRun> runs;
  StudyOptions study;
  std::int64_t shard = 0, shards = 1;
  try {
    definition = load_sweep(o.study);
    runs = definition.expand();
    apply_method_options(o.methods, study);
    if (!o.shard.empty()) {
      const auto slash = o.shard.find('/');
      if (slash == std::string::npos) throw std::invalid_argument("--shard: write i/n, e.g. 3/10");
      shard = std::stoll(o.shard.substr(0, slash));
      shards = std::stoll(o.shard.substr(slash + 1));
      if (shards < 1 || shard < 0 || shard >= shards) throw std::invalid_argument("--shard i/n needs 0 <= i < n");
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  for (const auto& run : runs) {
    if (const auto errors = run.scene.validate(); !errors.empty()) {
      spdlog::error("{}: run {} has an invalid scene: {}", o.study, run.index, errors.front());
      return 2;
    }
  }
  const std::uint64_t id = study_id(definition);
  std::set<std::int64_t> done;
  try {
    done = finished_runs(o.output, id);
    std::error_code ec;
    if (!std::filesystem::exists(o.output, ec) || std::filesystem::file_size(o.output, ec) == 0) {
      awcc::write_text_atomically(o.output, sweep_header() + "\n");
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  std::vector<const SweepRun*> pending;
  for (const auto& run : runs) {
    if (run.index % shards != shard || done.count(run.index)) continue;
    pending.push_back(&run);
  }
  spdlog::info("{}: {} runs in the study, {} already in {}, {} to run{}", o.study, runs.size(), done.size(), o.output,
               pending.size(), shards > 1 ? fmt::format(" (shard {}/{})", shard, shards) : "");
  const int fd = ::open(o.output.c_str(), O_WRONLY | O_APPEND);
  if (fd < 0) {
    spdlog::error("{}: cannot open for appending: {}", o.output, std::strerror(errno));
    return 1;
  }
  const unsigned threads = o.threads > 0 ? static_cast<unsigned>(o.threads)
                                         : std::max(1u, std::thread::hardware_concurrency());
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> finished{0};
  std::mutex write_mutex;
  std::string failure;
  Progress progress("sweeping");
  auto worker = [&]() {
    for (;;) {
      const std::size_t i = next++;
      if (i >= pending.size()) return;
      const SweepRun& run = *pending[i];
      StudyOptions options = study;
      options.awcc.np = run.np;
      std::string row;
      try {
        const RunResult r = run_scene(run.scene, options);
        row = sweep_row(run, &r, "", id);
      } catch (const std::exception& e) {
        row = sweep_row(run, nullptr, e.what(), id);
      }
      std::lock_guard lock(write_mutex);
      try {
        // One write per row, then to disk: a crash loses no finished row.
        write_all(fd, row + "\n", o.output);
        ::fdatasync(fd);
      } catch (const std::exception& e) {
        failure = e.what();
        next = pending.size();
        return;
      }
      progress(static_cast<double>(++finished) / static_cast<double>(pending.size()));
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < std::min<std::size_t>(threads, pending.size()); ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  ::close(fd);
  if (!failure.empty()) {
    spdlog::error("{}", failure);
    return 1;
  }
  spdlog::info("{}: {} runs written", o.output, finished.load());
  return 0;
}

}  // namespace pdp
