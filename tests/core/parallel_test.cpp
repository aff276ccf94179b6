#include "awcc/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
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
TEST(ParallelFor, AnExceptionStopsTheWorkAndIsRethrown) {
  std::atomic<int> started{0};
  EXPECT_THROW(awcc::parallel_for(100000, 2,
                                  [&](std::size_t i) {
                                    ++started;
                                    if (i == 10) throw std::runtime_error("item 10");
                                  }),
               std::runtime_error);
  EXPECT_LT(started.load(), 100000);
}

}  // namespace
