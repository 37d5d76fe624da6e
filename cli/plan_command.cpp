// `subflow plan DATASET --out DIR --chunk N [--overlap K] [--slurm]` writes a plan of
// `reconstruct` over chunks of frames (output/plan.h, docs/cluster.md); `subflow run-plan
// DIR [--task ID]` runs its tasks here, one after another, skipping the finished ones.
#include <filesystem>
#include <memory>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/plan_runner.h"
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

struct RunPlanArguments {
  std::string directory, task;
};

void RunRunPlan(const RunPlanArguments& arguments) {
  const nlohmann::json plan = output::ReadPlan(arguments.directory);
  const Stopwatch start;
  RunPlanTasks(arguments.directory, plan, arguments.task);
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
