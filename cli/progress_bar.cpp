#include "cli/progress_bar.h"

#include <unistd.h>

#include <cstdio>

namespace subflow::cli {

ProgressBar::ProgressBar() : interactive_(isatty(fileno(stderr)) != 0) {}

void ProgressBar::Begin(const std::string& stage, std::size_t total) {
  std::lock_guard<std::mutex> lock(mutex_);
  stage_ = stage;
  total_ = total;
  done_ = 0;
  last_printed_decile_ = -1;
  stopwatch_.Restart();
  Draw(false);
}

void ProgressBar::Update(std::size_t done) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ = done;
  Draw(false);
}

void ProgressBar::End() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (total_ > 0) done_ = total_;
  Draw(true);
}

void ProgressBar::Draw(bool final_line) {
  const double seconds = stopwatch_.Seconds();
  const double fraction = total_ > 0 ? static_cast<double>(done_) / total_ : 0.0;
  if (!interactive_ && !final_line) {
    // The complete line is End's alone: printing it here too (when an Update reaches the
    // total, or for a stage without a total) would print the stage's last line twice.
    if (total_ == 0 || done_ >= total_) return;
    const int decile = static_cast<int>(fraction * 10);
    if (decile == last_printed_decile_) return;
    last_printed_decile_ = decile;
  }
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  std::string bar(filled, '#');
  bar.resize(kWidth, '.');
  if (total_ > 0)
    std::fprintf(stderr, "%s%-28s [%s] %zu/%zu %.1fs%s", interactive_ ? "\r" : "",
                 stage_.c_str(), bar.c_str(), done_, total_, seconds,
                 interactive_ && !final_line ? "" : "\n");
  else
    std::fprintf(stderr, "%s%-28s %.1fs%s", interactive_ ? "\r" : "", stage_.c_str(), seconds,
                 interactive_ && !final_line ? "" : "\n");
  std::fflush(stderr);
}

}  // namespace subflow::cli
