// Progress reporting: library code reports through this interface (never std::cout);
// the CLI renders it as a bar. A null Progress* means "report nothing".
// The helpers below are also the points where long work stops when SIGINT / SIGTERM
// arrived (core/interrupt.h): each records the stage and may throw subflow::Interrupted.
#pragma once

#include <cstddef>
#include <string>

#include "core/interrupt.h"

namespace subflow {

class Progress {
 public:
  virtual ~Progress() = default;
  // Starts a stage of `total` steps (total 0 = unknown length).
  virtual void Begin(const std::string& stage, std::size_t total) = 0;
  // Reports that `done` of the stage's steps are complete.
  virtual void Update(std::size_t done) = 0;
  // Ends the current stage.
  virtual void End() = 0;
};

// Helpers that accept a null Progress*.
inline void ProgressBegin(Progress* p, const std::string& stage, std::size_t total) {
  ThrowIfInterrupted();
  LogStageBegin(stage, total);
  if (p) p->Begin(stage, total);
}
inline void ProgressUpdate(Progress* p, std::size_t done) {
  LogStageUpdate(done);
  if (p) p->Update(done);
  ThrowIfInterrupted();
}
inline void ProgressEnd(Progress* p) {
  LogStageEnd();
  if (p) p->End();
  ThrowIfInterrupted();
}

}  // namespace subflow
