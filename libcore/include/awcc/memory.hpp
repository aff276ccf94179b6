#pragma once
// How the process's allocator keeps memory between the runs of one thread.
//
// A study or sweep runs thousands of scenes per worker thread, each
// allocating and freeing the same tens of MB (the velocity steps kept for
// the pierce walk, the air intervals, FSCC's arrays). glibc's defaults give
// blocks above 128 kB (raised dynamically to at most 32 MB) to mmap and back
// to the system when freed, and trim the heap's free top above 128 kB, so
// every run faults the same pages in again: each fault a kernel entry and a
// page zeroed. On a paravirtualised machine that was 18 % of a 300 s base-case
// run (docs/performance.md, "Memory kept between runs").

namespace awcc {

/// Keeps freed memory in the process for the next allocation (blocks up to
/// 32 MB from the heap, the heap never trimmed), so repeated runs reuse
/// pages already mapped. Costs nothing in results; the process's memory stays
/// at its peak until exit instead of falling back after each run. Call once,
/// from main(), before the work starts: it is a process-wide setting, so the
/// libraries never call it (the Python module leaves its host's allocator
/// alone). Returns false where the C library offers no such control (not
/// glibc, or an allocator replaced by a sanitizer), which changes no result.
bool keep_freed_memory();

}  // namespace awcc
