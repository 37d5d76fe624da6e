// The process's peak resident memory so far, for the figures report.json records after each
// stage (the stage that raised it to its final value is where a run's peak is).
#pragma once

#include <sys/resource.h>

namespace subflow {

// Bytes (getrusage's ru_maxrss, which Linux counts in KiB); 0 when the system does not say.
inline long long PeakResidentBytes() {
  struct rusage usage {};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<long long>(usage.ru_maxrss) * 1024;
}

}  // namespace subflow
