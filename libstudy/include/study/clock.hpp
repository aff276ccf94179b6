#pragma once
// The clocks of the studies: wall seconds of a stage, and the CPU seconds of
// the calling thread that a method costs (what pdp bench and pdp design
// report, unaffected by other threads sharing the machine).

#include <chrono>

namespace study {

/// Seconds since `start`.
double seconds_since(std::chrono::steady_clock::time_point start);

/// CPU seconds of the calling thread.
double thread_seconds();

/// The CPU seconds f() takes on this thread.
template <class F>
double cost(F&& f) {
  const double t0 = thread_seconds();
  f();
  return thread_seconds() - t0;
}

}  // namespace study
