#include "cli/plan_runner.h"

#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <thread>
#include <vector>

#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/interrupt.h"
#include "core/json_reader.h"
#include "core/stopwatch.h"
#include "output/plan.h"
#include "output/result_writer.h"

namespace subflow::cli {
namespace {

namespace fs = std::filesystem;

// Runs `argv` (a subflow subcommand) as a child process of this binary; returns its exit
// code (128 + signal when killed) and its peak resident memory in *max_rss_kib. A stop
// requested of this process (core/interrupt.h) is passed on to the child once.
int RunChild(const std::vector<std::string>& argv, long* max_rss_kib) {
  const std::string binary = fs::read_symlink("/proc/self/exe").string();
  std::vector<char*> pointers;
  pointers.push_back(const_cast<char*>(binary.c_str()));
  for (const std::string& argument : argv) pointers.push_back(const_cast<char*>(argument.c_str()));
  pointers.push_back(nullptr);
  const pid_t parent = getpid();
  // SIGINT and SIGTERM blocked from before the fork until the task has its own handlers
  // (core/interrupt.h unblocks them): one arriving in between stays pending for the task,
  // instead of being recorded by this process's handler in the child and lost at exec.
  sigset_t stops, before;
  sigemptyset(&stops);
  sigaddset(&stops, SIGINT);
  sigaddset(&stops, SIGTERM);
  sigprocmask(SIG_BLOCK, &stops, &before);
  const pid_t child = fork();
  if (child < 0) {
    sigprocmask(SIG_SETMASK, &before, nullptr);
    ThrowError("run-plan", "", std::string("fork failed: ") + std::strerror(errno));
  }
  if (child == 0) {
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    // Its own process group, so that a Ctrl-C at the terminal reaches the task once, from
    // here (a second SIGINT would kill it before it stops cleanly); and it stops when this
    // process dies without passing anything on.
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(128 + SIGTERM);
    execv(binary.c_str(), pointers.data());
    _exit(127);
  }
  sigprocmask(SIG_SETMASK, &before, nullptr);
  int status = 0;
  struct rusage usage {};
  bool passed_on = false;
  for (;;) {
    const pid_t done = wait4(child, &status, WNOHANG, &usage);
    if (done == child) break;
    if (done < 0 && errno != EINTR) ThrowError("run-plan", "", std::string("wait failed: ") + std::strerror(errno));
    const int signal_number = PendingInterrupt();
    if (signal_number != 0 && !passed_on) {
      kill(child, signal_number);
      passed_on = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  *max_rss_kib = usage.ru_maxrss;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

// Runs task `task` of the plan in `directory` unless finished; records its status.
nlohmann::json RunTask(const std::string& directory, const nlohmann::json& plan, const nlohmann::json& task,
                       const std::string& position) {
  const std::string id = task.at("id").get<std::string>();
  nlohmann::json record = {{"id", id}, {"stage", task.value("stage", "")}, {"frames", task.value("frames", nlohmann::json())}};
  const fs::path status = fs::path(directory) / "status" / (id + ".json");
  if (output::TaskFinished(task)) {
    spdlog::info("run-plan: {} finished already (skipped)", id);
    record["skipped"] = true;
    if (fs::is_regular_file(status)) {  // what its run recorded
      const nlohmann::json recorded = ReadJsonFile(status.string(), "a task's status (run-plan)");
      record["seconds"] = recorded.value("seconds", 0.0);
      record["max_rss_kib"] = recorded.value("max_rss_kib", 0);
    }
    return record;
  }
  ThrowIfInterrupted();
  for (const auto& dependency : task.at("depends_on"))
    for (const nlohmann::json& other : plan.at("tasks"))
      if (other.at("id") == dependency && !output::TaskFinished(other))
        ThrowError((fs::path(directory) / "plan.json").string(), "task " + id,
                   "depends on " + dependency.get<std::string>() + ", which has not finished");
  spdlog::info("run-plan: {} ({} frames {}, {})", id, task.value("stage", ""),
               task.value("frames", nlohmann::json()).dump(), position);
  LogStageBegin("task " + id, 0);
  const Stopwatch start;
  long max_rss_kib = 0;
  // Its folder may hold the result of another plan's task: no longer finished from here on.
  if (fs::exists(task.at("output").get<std::string>())) output::ForgetTaskFinished(task);
  const int exit_code = RunChild(task.at("argv").get<std::vector<std::string>>(), &max_rss_kib);
  const double seconds = start.Seconds();
  fs::create_directories(fs::path(directory) / "status");
  output::WriteJsonFile(status.string(),
                        {{"id", id},
                         {"stamp", task.at("stamp")},
                         {"exit_code", exit_code},
                         {"seconds", seconds},
                         {"max_rss_kib", max_rss_kib}});
  if (exit_code == 0) output::RecordTaskFinished(task);  // even when a stop came as it ended
  ThrowIfInterrupted();
  if (exit_code != 0)
    ThrowError((fs::path(directory) / "plan.json").string(), "task " + id,
               "failed (exit code " + std::to_string(exit_code) + "); run-plan again re-runs it and what follows");
  LogStageEnd();
  record["skipped"] = false;
  record["seconds"] = seconds;
  record["max_rss_kib"] = max_rss_kib;
  return record;
}

}  // namespace

nlohmann::json RunPlanTasks(const std::string& directory, const nlohmann::json& plan, const std::string& only) {
  nlohmann::json records = nlohmann::json::array();
  const std::size_t total = plan.at("tasks").size();
  for (std::size_t i = 0; i < total; ++i) {
    const nlohmann::json& task = plan.at("tasks")[i];
    if (!only.empty() && task.at("id") != only) continue;
    records.push_back(RunTask(directory, plan, task, "task " + std::to_string(i + 1) + " of " + std::to_string(total)));
  }
  if (records.empty()) ThrowError((fs::path(directory) / "plan.json").string(), "task", "no task \"" + only + "\"");
  return records;
}

}  // namespace subflow::cli
