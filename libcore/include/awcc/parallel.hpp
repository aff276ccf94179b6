#pragma once
// The one thread pool of the toolkit: work items [0, n) handed out in order
// to up to `threads` threads. Results are placed by index, so a computation
// gives the same numbers whatever the thread count.

#include <cstddef>
#include <functional>

namespace awcc {

/// Threads to use for n work items: `requested` (all cores when 0), at least
/// 1 and at most n.
unsigned thread_count(int requested, std::size_t n);

/// Runs fn(i) for every i in [0, n) on thread_count(threads, n) threads, the
/// calling thread being one of them. The first exception thrown by fn stops
/// the handing out of further items; it is rethrown once every thread has
/// finished its current item.
void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& fn);

}  // namespace awcc
