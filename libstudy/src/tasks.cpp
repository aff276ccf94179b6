#include "study/tasks.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fmt/format.h>
#include <mutex>

#include "awcc/errors.hpp"
#include "awcc/parallel.hpp"

namespace study {

AppendFile::AppendFile(std::string path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_APPEND);
  if (fd_ < 0) throw awcc::OutputError(fmt::format("{}: cannot open for appending: {}", path_, std::strerror(errno)));
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) ::close(fd_);
}

void AppendFile::append(const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw awcc::OutputError(fmt::format("{}: write failed: {}", path_, std::strerror(errno)));
    }
    done += static_cast<std::size_t>(n);
  }
  ::fdatasync(fd_);
}

void run_tasks(const std::vector<std::int64_t>& tasks, const std::function<std::string(std::int64_t)>& compute,
               const std::string& output, int threads, const Progress& progress) {
  AppendFile file(output);
  std::size_t finished = 0;
  std::mutex write_mutex;
  awcc::parallel_for(tasks.size(), threads, [&](std::size_t i) {
    const std::string text = compute(tasks[i]);
    std::lock_guard lock(write_mutex);
    // One write per task, then to disk: a crash loses no finished task. A
    // failed write stops the study (the pool hands out no further task).
    file.append(text);
    if (progress) progress(static_cast<double>(++finished) / static_cast<double>(tasks.size()));
  });
}

}  // namespace study
