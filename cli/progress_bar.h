// The terminal rendering of subflow::Progress: one line per stage on stderr, redrawn in
// place on a terminal, printed at 10 % steps otherwise (logs stay readable in CI).
#pragma once

#include <cstddef>
#include <mutex>
#include <string>

#include "core/progress.h"
#include "core/stopwatch.h"

namespace subflow::cli {

class ProgressBar : public Progress {
 public:
  ProgressBar();
  void Begin(const std::string& stage, std::size_t total) override;
  void Update(std::size_t done) override;
  void End() override;

 private:
  void Draw(bool final_line);

  std::mutex mutex_;
  bool interactive_ = false;
  std::string stage_;
  std::size_t total_ = 0;
  std::size_t done_ = 0;
  int last_printed_decile_ = -1;
  Stopwatch stopwatch_;
};

}  // namespace subflow::cli
