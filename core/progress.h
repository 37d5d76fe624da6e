// Progress reporting: library code reports through this interface (never std::cout);
// the CLI renders it as a bar. A null Progress* means "report nothing".
#pragma once

#include <cstddef>
#include <string>

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
  if (p) p->Begin(stage, total);
}
inline void ProgressUpdate(Progress* p, std::size_t done) {
  if (p) p->Update(done);
}
inline void ProgressEnd(Progress* p) {
  if (p) p->End();
}

}  // namespace subflow
