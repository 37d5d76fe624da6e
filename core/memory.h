// The process's memory as the stages see it: its peak resident size so far, for the figures
// report.json records after each stage (the stage that raised it to its final value is
// where a run's peak is), and the freed memory the allocator still holds, given back
// between stages.
#pragma once

#include <sys/resource.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace subflow {

// Bytes (getrusage's ru_maxrss, which Linux counts in KiB); 0 when the system does not say.
inline long long PeakResidentBytes() {
  struct rusage usage {};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<long long>(usage.ru_maxrss) * 1024;
}

// The solvers allocate and free arrays of megabytes on every step (sample and constraint
// arrays, CG vectors, Ceres's Jacobians). glibc gives blocks above its mmap threshold
// (dynamic, at most 32 MB) and a heap top above its trim threshold back to the kernel at
// once, and the next step faults every page in again: on this paravirtualized machine that
// was ~10 % of a stage's time in the kernel (docs/speed.md, "Memory given back and faulted
// in again"). Freed blocks up to 256 MB now stay in the process, and the next step's
// arrays of the same sizes reuse them. Set once, at the start of main. Measured peak:
// blob 0.97 → 0.99 GB, pose2sim 3.80 → 3.69 GB.
inline void KeepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
#endif
}

// Gives the pages of freed heap blocks back to the system (glibc's malloc_trim; a no-op
// elsewhere). Within a stage, `subflow` keeps freed blocks for the next step's arrays of
// the same sizes (KeepFreedMemoryForReuse); between two stages of `reconstruct` they only fragment the
// heap, and the next stage, allocating other sizes, grew the process beyond them: on Pose2Sim's
// single-person take the retrack peaked at 3.1 GB alone and at 4.1 GB after the refinement
// in one process (docs/speed.md, "Memory between stages").
inline void ReleaseFreeMemory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace subflow
