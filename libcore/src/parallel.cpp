#include "awcc/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace awcc {

unsigned thread_count(int requested, std::size_t n) {
  unsigned t = requested > 0 ? static_cast<unsigned>(requested) : std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::clamp<std::size_t>(t, 1, std::max<std::size_t>(n, 1)));
}

void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& fn) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto work = [&] {
    try {
      for (std::size_t i; (i = next.fetch_add(1)) < n;) fn(i);
    } catch (...) {
      std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = n;
    }
  };
  const unsigned t = thread_count(threads, n);
  std::vector<std::thread> pool;
  pool.reserve(t - 1);
  try {
    for (unsigned i = 1; i < t; ++i) pool.emplace_back(work);
  } catch (...) {
    // No more threads to be had (a process limit): the ones running and this
    // one finish the work.
  }
  work();
  for (auto& th : pool) th.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace awcc
