#pragma once
// pdp sweep's and pdp design's tasks on threads (study::run_tasks) or over
// MPI ranks: MPI lives here, in the program that owns the process (its
// start and end), not in the study library a script or the Python module
// links.

#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace pdp {

/// MPI, initialised only when started by mpirun (so that a plain run needs
/// no MPI daemon) and when pdp was built with it; finalised on destruction.
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  [[nodiscard]] bool on() const { return on_; }
  [[nodiscard]] int rank() const { return rank_; }
  [[nodiscard]] int size() const { return size_; }
  /// The writer's (rank 0) exit code so far and finished tasks, to every rank.
  void share(int& code, std::set<std::int64_t>& done) const;

 private:
  bool on_ = false;
  int rank_ = 0, size_ = 1;
};

/// "i/n" of --shard: (i, n) with 0 <= i < n; throws std::invalid_argument.
std::pair<std::int64_t, std::int64_t> parse_shard(const std::string& text);

/// study::run_tasks, or over the ranks when `mpi` has more than one (rank 0
/// writes and hands out tasks one at a time). Progress on a terminal under
/// `label`. Returns an exit code (docs/guide/settings.md, "Exit status").
int run_tasks(const std::vector<std::int64_t>& tasks, const std::function<std::string(std::int64_t)>& compute,
              const std::string& output, int threads, const std::string& label, const MpiSession& mpi);

}  // namespace pdp
