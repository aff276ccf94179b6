#pragma once
// What the pdp subcommands share about the terminal: progress on stderr when
// it is a terminal, and resource figures for the log.

#include <chrono>
#include <string>
#include <string_view>

namespace pdp {

/// A one-line progress indicator on stderr, drawn only when stderr is a
/// terminal and at most ten times a second.
class Progress {
 public:
  explicit Progress(std::string label);
  ~Progress();
  void operator()(double fraction);

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point last_{};
};

/// Peak resident memory of this process, MB.
double peak_memory_mb();

/// Seconds since `start`.
double seconds_since(std::chrono::steady_clock::time_point start);

/// CPU seconds of the calling thread: a method's cost, unaffected by other
/// threads sharing the machine.
double thread_seconds();

/// The CPU seconds f() takes on this thread.
template <class F>
double cost(F&& f) {
  const double t0 = thread_seconds();
  f();
  return thread_seconds() - t0;
}

}  // namespace pdp
