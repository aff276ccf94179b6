#pragma once
// What the pdp subcommands share about the terminal: progress on stderr when
// it is a terminal, and resource figures for the log (the clocks of the
// studies are the study library's: study/clock.hpp).

#include <chrono>
#include <string>

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

}  // namespace pdp
