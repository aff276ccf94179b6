#include "awcc/memory.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>  // and, through it, __GLIBC__ where the C library is glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace {

// A sanitizer replaces the allocator: GCC says so by __SANITIZE_*__, clang by __has_feature.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define PDP_SANITIZED_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define PDP_SANITIZED_ALLOCATOR 1
#endif
#endif

#if defined(__GLIBC__) && !defined(PDP_SANITIZED_ALLOCATOR)
// A 20 MB block, freed and asked for again, must come from the heap both
// times and stay there in between. glibc's defaults fail both: the first
// block of this test process is above the initial 128 kB mmap threshold
// (hblks grows) and the heap's top is trimmed back to the system when freed
// (arena falls). Each test runs in its own process (gtest_discover_tests),
// so no earlier free has raised the dynamic threshold.
TEST(Memory, AFreedBlockStaysInTheHeapForTheNextRun) {
  ASSERT_TRUE(awcc::keep_freed_memory());
  constexpr std::size_t bytes = 20u << 20;
  const auto before = mallinfo2();
  void* block = std::malloc(bytes);
  ASSERT_NE(block, nullptr);
  std::memset(block, 1, bytes);  // the pages faulted in
  const auto held = mallinfo2();
  EXPECT_EQ(held.hblks, before.hblks) << "the block went to mmap";
  EXPECT_GE(held.arena, before.arena + bytes);
  std::free(block);
  const auto after = mallinfo2();
  EXPECT_GE(after.arena, before.arena + bytes) << "the heap was trimmed: the next run faults its pages in again";
  EXPECT_GE(after.fordblks, bytes);
}

TEST(Memory, BlocksAboveTheLimitStillGoToTheSystem) {
  ASSERT_TRUE(awcc::keep_freed_memory());
  // 64 MB: a whole recording's samples, kept out of the heap so that the
  // heap does not grow by it for ever.
  const auto before = mallinfo2();
  void* block = std::malloc(64u << 20);
  ASSERT_NE(block, nullptr);
  EXPECT_EQ(mallinfo2().hblks, before.hblks + 1);
  std::free(block);
}
#else
TEST(Memory, ReportsNoControlWithoutGlibcsAllocator) {
  // A sanitizer's allocator ignores mallopt; the call must say so, not
  // pretend.
  EXPECT_FALSE(awcc::keep_freed_memory());
}
#endif

}  // namespace
