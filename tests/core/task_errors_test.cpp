// RunSideBySide / TaskErrors (core/task_errors.h): a task's exception reaches the caller
// once every task has returned, and never cuts another task's nested parallel loops short
// (which TBB's cancellation does when an exception reaches it).
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/task_errors.h"

namespace subflow {
namespace {

// Waits (at most two seconds: on one thread the other task may run only afterwards) until
// `flag` is set, and a little longer for the exception to have travelled.
void AwaitFlag(const std::atomic<bool>& flag) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (!flag.load() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

TEST(TaskErrors, AThrowingTaskDoesNotCutTheOthersNestedLoopsShort) {
  constexpr int kIterations = 20000;
  std::atomic<bool> thrown{false};
  std::atomic<int> iterations{0};
  bool other_finished = false;
  try {
    RunSideBySide(
        [&] {
          thrown.store(true);
          throw std::runtime_error("stop");
        },
        [&] {
          AwaitFlag(thrown);
          tbb::parallel_for(0, kIterations, [&](int) { iterations.fetch_add(1); });
          other_finished = true;
        });
    ADD_FAILURE() << "the exception did not reach the caller";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "stop");
  }
  EXPECT_TRUE(other_finished);
  EXPECT_EQ(iterations.load(), kIterations) << "the other task's nested loop was cancelled";
}

TEST(TaskErrors, TheFirstExceptionIsRethrownAndFailedTellsTheOthers) {
  TaskErrors errors;
  EXPECT_FALSE(errors.failed());
  EXPECT_TRUE(errors.Run([] {}));
  EXPECT_NO_THROW(errors.RethrowFirst());
  EXPECT_FALSE(errors.Run([] { throw std::invalid_argument("first"); }));
  EXPECT_TRUE(errors.failed());
  EXPECT_FALSE(errors.Run([] { throw std::out_of_range("second"); }));
  EXPECT_THROW(errors.RethrowFirst(), std::invalid_argument);
}

// A task that takes the group's TaskErrors sees another task's exception and stops early;
// the caller still gets that exception. Needs two threads: on one, the tasks run one after
// the other and the throwing one may come second.
TEST(TaskErrors, ATaskThatTakesTheGroupStopsOnceAnotherHasThrown) {
  if (tbb::this_task_arena::max_concurrency() < 2) GTEST_SKIP() << "needs two threads; TBB has one here";
  std::atomic<bool> thrown{false};
  bool stopped_early = false;
  try {
    RunSideBySide(
        [&] {
          thrown.store(true);
          throw std::runtime_error("bad frame");
        },
        [&](const TaskErrors& group) {
          AwaitFlag(thrown);
          const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
          while (!group.failed() && std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
          stopped_early = group.failed();
        });
    ADD_FAILURE() << "the exception did not reach the caller";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "bad frame");
  }
  EXPECT_TRUE(stopped_early) << "the task never saw the other's exception";
}

TEST(TaskErrors, TasksThatDoNotThrowAllRun) {
  std::atomic<int> ran{0};
  RunSideBySide([&] { ran += 1; }, [&] { ran += 10; }, [&] { ran += 100; });
  EXPECT_EQ(ran.load(), 111);
}

}  // namespace
}  // namespace subflow
