// `subflow plan DATASET --out DIR --chunk N [--overlap K] [--slurm]` writes a plan of
// `reconstruct` over chunks of frames (output/plan.h, docs/cluster.md); `subflow run-plan
// DIR [--task ID]` runs its tasks here, one after another, skipping the finished ones.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <memory>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/stage_options.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "output/plan.h"
#include "output/result_writer.h"
#include "vision/dataset.h"

namespace subflow::cli {
namespace {

namespace fs = std::filesystem;

struct PlanArguments {
  std::string dataset, out;
  bool overwrite = false;
  output::PlanOptions plan;
  ReconstructionArguments stages;
};

void RunPlan(const PlanArguments& arguments) {
  const solver::ReconstructionOptions options = arguments.stages.Options();
  arguments.plan.Check();
  const vision::Dataset dataset(arguments.dataset);
  // A folder holding a plan already: WritePlan decides (CheckReplan), keeping what is
  // still valid; any other folder as every command's output.
  if (!fs::is_regular_file(fs::path(arguments.out) / "plan.json"))
    output::PrepareOutputDirectory(arguments.out, arguments.overwrite);
  const nlohmann::json plan = output::WritePlan(arguments.dataset, dataset, options, arguments.plan, arguments.out,
                                                arguments.overwrite, InvocationArguments());
  spdlog::info("plan: {} tasks over frames {} in {} chunks written to {}{}", plan["tasks"].size(),
               plan["frames"].dump(), plan["chunks"].get<int>(), arguments.out,
               arguments.plan.slurm ? " (sbatch scripts in slurm/, submit with slurm/submit.sh)" : "");
}

// Runs `argv` (a subflow subcommand) as a child process of this binary; returns its exit
// code (128 + signal when killed) and its peak resident memory in *max_rss_kib.
int RunChild(const std::vector<std::string>& argv, long* max_rss_kib) {
  const std::string binary = fs::read_symlink("/proc/self/exe").string();
  std::vector<char*> pointers;
  pointers.push_back(const_cast<char*>(binary.c_str()));
  for (const std::string& argument : argv) pointers.push_back(const_cast<char*>(argument.c_str()));
  pointers.push_back(nullptr);
  const pid_t child = fork();
  if (child < 0) ThrowError("run-plan", "", std::string("fork failed: ") + std::strerror(errno));
  if (child == 0) {
    execv(binary.c_str(), pointers.data());
    _exit(127);
  }
  int status = 0;
  struct rusage usage {};
  if (wait4(child, &status, 0, &usage) < 0) ThrowError("run-plan", "", std::string("wait failed: ") + std::strerror(errno));
  *max_rss_kib = usage.ru_maxrss;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

// Runs task `task` of the plan in `directory` unless finished; records its status.
void RunTask(const std::string& directory, const nlohmann::json& plan, const nlohmann::json& task) {
  const std::string id = task.at("id").get<std::string>();
  if (output::TaskFinished(task)) {
    spdlog::info("run-plan: {} finished already (skipped)", id);
    return;
  }
  for (const auto& dependency : task.at("depends_on"))
    for (const nlohmann::json& other : plan.at("tasks"))
      if (other.at("id") == dependency && !output::TaskFinished(other))
        ThrowError((fs::path(directory) / "plan.json").string(), "task " + id,
                   "depends on " + dependency.get<std::string>() + ", which has not finished");
  spdlog::info("run-plan: {} ({} frames {})", id, task.value("stage", ""), task.value("frames", nlohmann::json()).dump());
  const Stopwatch start;
  long max_rss_kib = 0;
  // Its folder may hold the result of another plan's task: no longer finished from here on.
  if (fs::exists(task.at("output").get<std::string>())) output::ForgetTaskFinished(task);
  const int exit_code = RunChild(task.at("argv").get<std::vector<std::string>>(), &max_rss_kib);
  fs::create_directories(fs::path(directory) / "status");
  output::WriteJsonFile((fs::path(directory) / "status" / (id + ".json")).string(),
                        {{"id", id},
                         {"stamp", task.at("stamp")},
                         {"exit_code", exit_code},
                         {"seconds", start.Seconds()},
                         {"max_rss_kib", max_rss_kib}});
  if (exit_code != 0)
    ThrowError((fs::path(directory) / "plan.json").string(), "task " + id,
               "failed (exit code " + std::to_string(exit_code) + "); run-plan again re-runs it and what follows");
  output::RecordTaskFinished(task);
}

struct RunPlanArguments {
  std::string directory, task;
};

void RunRunPlan(const RunPlanArguments& arguments) {
  const nlohmann::json plan = output::ReadPlan(arguments.directory);
  const Stopwatch start;
  int run = 0;
  for (const nlohmann::json& task : plan.at("tasks")) {
    if (!arguments.task.empty() && task.at("id") != arguments.task) continue;
    RunTask(arguments.directory, plan, task);
    ++run;
  }
  if (run == 0)
    ThrowError((fs::path(arguments.directory) / "plan.json").string(), "task", "no task \"" + arguments.task + "\"");
  spdlog::info("run-plan: done in {:.1f} s; result in {}", start.Seconds(), plan.value("result", std::string()));
}

}  // namespace

Command AddPlanCommand(CLI::App& app) {
  auto arguments = std::make_shared<PlanArguments>();
  CLI::App* sub = app.add_subcommand(
      "plan", "Cut reconstruct into tasks over chunks of frames (plan.json; --slurm: sbatch scripts) for run-plan "
              "or a Slurm cluster (docs/cluster.md)");
  AddDatasetAndOutput(sub, &arguments->dataset, &arguments->out, &arguments->overwrite);
  sub->add_option("--chunk", arguments->plan.chunk, "Frames per chunk")->capture_default_str()->check(CLI::Range(2, 1 << 30));
  sub->add_option("--overlap", arguments->plan.overlap,
                  "Frames a refinement chunk reaches into each neighbouring chunk")
      ->capture_default_str()->check(CLI::Range(0, 1 << 30));
  sub->add_flag("--slurm", arguments->plan.slurm, "Also write sbatch scripts and slurm/submit.sh");
  sub->add_option("--memory", arguments->plan.memory_mib,
                  "Memory per Slurm task, MiB (0 = 1.5 x the peak a run-plan of the plan measured, else 4096)")
      ->capture_default_str()->check(CLI::Range(0, 1 << 30));
  AddReconstructionOptions(sub, &arguments->stages);
  return {sub, [arguments] { RunPlan(*arguments); }};
}

Command AddRunPlanCommand(CLI::App& app) {
  auto arguments = std::make_shared<RunPlanArguments>();
  CLI::App* sub = app.add_subcommand(
      "run-plan", "Run a plan's tasks here, one after another; finished tasks (output complete) are skipped");
  sub->add_option("DIR", arguments->directory, "Directory of the plan (subflow plan --out)")
      ->required()->check(CLI::ExistingDirectory);
  sub->add_option("--task", arguments->task, "Run only this task (as the Slurm jobs do)");
  return {sub, [arguments] { RunRunPlan(*arguments); }};
}

}  // namespace subflow::cli
