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

// Gives the pages of freed heap blocks back to the system (glibc's malloc_trim; a no-op
// elsewhere). Within a stage, `subflow` keeps freed blocks for the next step's arrays of
// the same sizes (cli/main.cpp); between two stages of `reconstruct` they only fragment the
// heap, and the next stage, allocating other sizes, grew the process beyond them: on Pose2Sim's
// single-person take the retrack peaked at 3.1 GB alone and at 4.1 GB after the refinement
// in one process (docs/speed.md, "Memory between stages").
inline void ReleaseFreeMemory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace subflow
