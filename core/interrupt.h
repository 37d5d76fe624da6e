// Stopping cleanly on SIGINT / SIGTERM. InstallInterruptHandlers() (the CLI, once) makes
// both signals set a flag — the handler does nothing else, so it is async-signal-safe —
// and restores the default action, so a second signal kills at once. Long work checks the
// flag at its progress points (core/progress.h calls ThrowIfInterrupted, and so does the
// writing of each mesh and PNG, geometry/mesh_io.h, vision/dataset_writer.h): it throws
// subflow::Interrupted, which unwinds like any error, so every AtomicFile
// (core/atomic_file.h) not yet committed removes its temporary, and no report.json is
// written for the unfinished run. The CLI catches it, prints "interrupted: <what was
// finished>" and exits with 128 + the signal's number (130 for SIGINT, 143 for SIGTERM).
//
// The flag and the record of finished stages are process-wide by nature (a signal
// reaches the process, not a stage), hence the one global state of subflow.
#pragma once

#include <signal.h>

#include <atomic>
#include <csignal>
#include <cstddef>
#include <exception>
#include <mutex>
#include <string>
#include <vector>

namespace subflow {

// Thrown at a progress point once SIGINT or SIGTERM arrived. Deliberately not a
// subflow::Error, so no handler of bad input swallows it.
class Interrupted : public std::exception {
 public:
  Interrupted(int signal_number, std::string what) : signal_(signal_number), what_(std::move(what)) {}
  const char* what() const noexcept override { return what_.c_str(); }
  int signal_number() const { return signal_; }

 private:
  int signal_;
  std::string what_;
};

namespace interrupt_detail {
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs a lock-free flag");
inline std::atomic<int> pending_signal{0};
inline void RecordSignal(int signal_number) { pending_signal.store(signal_number); }

// What the run has done so far, in the words of its progress stages.
struct WorkLog {
  std::mutex mutex;
  std::vector<std::string> finished;
  std::string current;
  std::size_t done = 0, total = 0;
};
inline WorkLog& Log() {
  static WorkLog log;
  return log;
}
}  // namespace interrupt_detail

// Makes SIGINT and SIGTERM request a clean stop (see above). Call once, before the work.
inline void InstallInterruptHandlers() {
  struct sigaction action {};
  action.sa_handler = interrupt_detail::RecordSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND | SA_RESTART;  // a second signal gets the default action
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // A task started by run-plan or a chunked reconstruct (cli/plan_runner.cpp) starts with
  // both blocked, so that a stop arriving before its handlers exist stays pending: now.
  sigset_t stops;
  sigemptyset(&stops);
  sigaddset(&stops, SIGINT);
  sigaddset(&stops, SIGTERM);
  sigprocmask(SIG_UNBLOCK, &stops, nullptr);
}

// The signal that requested a stop, 0 when none did.
inline int PendingInterrupt() { return interrupt_detail::pending_signal.load(); }

// For tests: forget a requested stop and the work log.
inline void ResetInterruptState() {
  interrupt_detail::pending_signal.store(0);
  interrupt_detail::WorkLog& log = interrupt_detail::Log();
  const std::lock_guard<std::mutex> lock(log.mutex);
  log.finished.clear();
  log.current.clear();
  log.done = log.total = 0;
}

// Progress points record the work (core/progress.h calls these).
inline void LogStageBegin(const std::string& stage, std::size_t total) {
  interrupt_detail::WorkLog& log = interrupt_detail::Log();
  const std::lock_guard<std::mutex> lock(log.mutex);
  log.current = stage;
  log.done = 0;
  log.total = total;
}
inline void LogStageUpdate(std::size_t done) {
  interrupt_detail::WorkLog& log = interrupt_detail::Log();
  const std::lock_guard<std::mutex> lock(log.mutex);
  log.done = done;
}
inline void LogStageEnd() {
  interrupt_detail::WorkLog& log = interrupt_detail::Log();
  const std::lock_guard<std::mutex> lock(log.mutex);
  if (!log.current.empty()) log.finished.push_back(log.current);
  log.current.clear();
}

// "finished: visual hull, fit subdivision surface; stopped in motion initialization at
// 3/8" — what the run had done when it stopped.
inline std::string FinishedWork() {
  interrupt_detail::WorkLog& log = interrupt_detail::Log();
  const std::lock_guard<std::mutex> lock(log.mutex);
  std::string text = "finished: ";
  if (log.finished.empty()) text += "nothing";
  for (std::size_t i = 0; i < log.finished.size(); ++i) text += (i ? ", " : "") + log.finished[i];
  if (!log.current.empty()) {
    text += "; stopped in " + log.current;
    if (log.total) text += " at " + std::to_string(log.done) + "/" + std::to_string(log.total);
  }
  return text;
}

// Throws Interrupted when a stop was requested.
inline void ThrowIfInterrupted() {
  const int signal_number = PendingInterrupt();
  if (signal_number == 0) return;
  throw Interrupted(signal_number, std::string(signal_number == SIGINT ? "SIGINT" : "SIGTERM") + " (" +
                                       FinishedWork() + ")");
}

}  // namespace subflow
