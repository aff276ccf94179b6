#pragma once
// The engine under sweeps and pdp design: tasks, named by index, computed on
// threads, each task's text (whole CSV lines) appended to one file in one
// write and flushed to disk, so that an interrupted study loses no finished
// task and resumes from what the file holds. (Spreading tasks over MPI ranks
// is the pdp tool's: it owns the process, and so MPI's start and end.)

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace study {

/// A file opened for appending whole tasks: each append is one write, then
/// flushed to disk. Throws awcc::OutputError naming the file when it cannot
/// be opened or written.
class AppendFile {
 public:
  explicit AppendFile(std::string path);
  ~AppendFile();
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  void append(const std::string& text);
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

/// Fraction of the tasks done, after each (called under the writer's lock).
using Progress = std::function<void(double)>;

/// Appends compute(task) for every task to `output` (which exists), on
/// `threads` threads (0 = all cores). A task that throws stops the study
/// (no further task is handed out) and its exception is rethrown.
void run_tasks(const std::vector<std::int64_t>& tasks, const std::function<std::string(std::int64_t)>& compute,
               const std::string& output, int threads, const Progress& progress = {});

}  // namespace study
