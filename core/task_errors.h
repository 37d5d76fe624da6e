// Tasks that run side by side with TBB (tbb::parallel_invoke, the steps of a pipeline) and
// may throw: an interrupt at a progress point (core/interrupt.h), bad input in one frame.
//
// An exception that reaches TBB cancels the task group, and the cancellation reaches every
// parallel loop nested in the tasks still running: such a loop returns as if it had
// finished, with part of its work undone, and its task goes on with half-computed arrays —
// garbage, or a crash — before the exception arrives where the tasks were started. (UBSan
// caught it: `subflow reconstruct` interrupted in motion initialization read an empty sum
// in the other chain.)
//
// So no exception reaches TBB. Each task runs through TaskErrors::Run, which keeps what it
// throws; the other tasks go on to their next progress point (where a stop request throws
// for them too) or ask failed() to stop early; and once all have returned, the caller
// rethrows the first exception kept. RunSideBySide does all of that for a parallel_invoke,
// and hands its TaskErrors to the tasks that take one: a chain of frames asks failed()
// before each step, so a bad frame in one chain does not wait for the other chain's last
// frame to be reported (whatever a stopped task leaves half done is never used: the
// exception follows).
#pragma once

#include <atomic>
#include <exception>
#include <mutex>
#include <type_traits>
#include <utility>

#include <tbb/parallel_invoke.h>

namespace subflow {

class TaskErrors {
 public:
  // Runs `task`, keeping what it throws. True when it returned normally.
  template <typename Task>
  bool Run(Task&& task) noexcept {
    try {
      std::forward<Task>(task)();
      return true;
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!first_) first_ = std::current_exception();
      failed_.store(true);
      return false;
    }
  }

  // Whether a task has thrown: the others may stop early.
  bool failed() const { return failed_.load(); }

  // Rethrows the first exception a task threw, if any. Call once the tasks have returned.
  void RethrowFirst() const {
    if (first_) std::rethrow_exception(first_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr first_;
  std::atomic<bool> failed_{false};
};

// Runs the tasks side by side (tbb::parallel_invoke) and, once all have returned, rethrows
// the first exception one of them threw. A task is never cut short by another's exception;
// a task callable with a `const TaskErrors&` gets the group's, to stop early itself once
// failed() says another task has thrown.
template <typename... Tasks>
void RunSideBySide(Tasks&&... tasks) {
  static_assert(sizeof...(Tasks) >= 2, "side by side takes two tasks or more");
  TaskErrors errors;
  const auto run = [&errors](auto& task) {
    if constexpr (std::is_invocable_v<decltype(task), const TaskErrors&>)
      errors.Run([&] { task(std::as_const(errors)); });
    else
      errors.Run(task);
  };
  tbb::parallel_invoke([&] { run(tasks); }...);
  errors.RethrowFirst();
}

}  // namespace subflow
