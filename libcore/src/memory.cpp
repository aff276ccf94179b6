#include "awcc/memory.hpp"

#include <cstdlib>  // defines __GLIBC__ where the C library is glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace awcc {

bool keep_freed_memory() {
#if defined(__GLIBC__)
  // 32 MB is the most glibc accepts (half its 64 MB per-thread heap); larger
  // blocks, rarer (a whole recording read at once), keep going to mmap.
  constexpr int mmap_threshold = 32 * 1024 * 1024;
  // M_TRIM_THRESHOLD takes an int: the largest stops trimming in practice.
  constexpr int never_trim = 0x7fffffff;
  return mallopt(M_MMAP_THRESHOLD, mmap_threshold) == 1 && mallopt(M_TRIM_THRESHOLD, never_trim) == 1;
#else
  return false;
#endif
}

}  // namespace awcc
