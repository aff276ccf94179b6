#include "awcc/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <stdexcept>
#include <vector>

namespace {

// Every item runs once, results by index: the same for any thread count.
TEST(ParallelFor, EveryItemOnceWhateverTheThreads) {
  for (int threads : {0, 1, 2, 7}) {
    std::vector<int> hits(1000, 0);
    awcc::parallel_for(hits.size(), threads, [&](std::size_t i) { hits[i] += static_cast<int>(i % 13) + 1; });
    for (std::size_t i = 0; i < hits.size(); ++i) ASSERT_EQ(hits[i], static_cast<int>(i % 13) + 1) << threads;
  }
  awcc::parallel_for(0, 4, [](std::size_t) { FAIL(); });
}

// The first exception reaches the caller, after which no new item starts.
// Items after the throwing one wait until it has thrown and then a
// millisecond (time for the pool to record it), so that the other thread
// cannot race through every item before the exception is seen: a pool that
// stops starts at most a few of them; one that does not starts all 100 000.
TEST(ParallelFor, AnExceptionStopsTheWorkAndIsRethrown) {
  std::atomic<int> started{0};
  std::atomic<bool> thrown{false};
  EXPECT_THROW(awcc::parallel_for(100000, 2,
                                  [&](std::size_t i) {
                                    ++started;
                                    if (i == 10) {
                                      thrown = true;
                                      throw std::runtime_error("item 10");
                                    }
                                    if (i > 10) {
                                      while (!thrown) std::this_thread::yield();
                                      std::this_thread::sleep_for(std::chrono::milliseconds(1));
                                    }
                                  }),
               std::runtime_error);
  EXPECT_LT(started.load(), 20);
}

}  // namespace
