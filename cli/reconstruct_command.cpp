// `subflow reconstruct DATASET --out DIR`: the product's main job, start to finish —
// shape initialization → motion initialization → stereo refinement (unless --no-refine)
// → re-tracking → rigid / non-rigid split (output/stage_pipeline.h: the stages of the
// stage commands, each writing its stage folder DIR/stages/<stage>/; --resume reuses the
// complete ones of an interrupted run). A take longer than --chunk frames runs as the plan
// of `subflow plan --chunk` (docs/cluster.md) in DIR/plan, its tasks one after another
// as child processes, so that memory follows the chunk, not the take.
#include <filesystem>
#include <memory>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/plan_runner.h"
#include "cli/progress_bar.h"
#include "cli/stage_options.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "output/plan.h"
#include "output/report.h"
#include "output/result_writer.h"
#include "output/stage_pipeline.h"
#include "vision/dataset.h"

namespace subflow::cli {
namespace {

struct ReconstructArguments {
  std::string dataset;
  std::string out;
  bool overwrite = false;
  bool resume = false;
  int chunk = 100;  // frames per chunk of a longer take (0 = one process whatever the length)
  ReconstructionArguments stages;
};

// The take as plan + run-plan in out/plan, then its result moved into out.
void RunChunkedReconstruct(const ReconstructArguments& arguments, const vision::Dataset& dataset,
                           const solver::ReconstructionOptions& options, const output::CommandRun& run, int frames,
                           const Stopwatch& start) {
  output::PlanOptions plan_options;
  plan_options.chunk = arguments.chunk;
  const std::string directory = (std::filesystem::path(arguments.out) / "plan").string();
  std::filesystem::create_directories(directory);
  spdlog::info("reconstruct: {} frames, more than --chunk {}: run as a plan of chunks in {} (docs/cluster.md)",
               frames, arguments.chunk, directory);
  // Replaces a plan of other options (its tasks whose stamps still hold stay finished):
  // without --resume, PrepareOutputDirectory removed any plan already.
  const nlohmann::json plan = output::WritePlan(arguments.dataset, dataset, options, plan_options, directory,
                                                /*overwrite=*/true, InvocationArguments());
  const nlohmann::json tasks = RunPlanTasks(directory, plan);
  output::AdoptPlanResult(plan, tasks, arguments.out, output::ReportHead(run, dataset), start.Seconds());
}

void RunReconstruct(const ReconstructArguments& arguments) {
  const Stopwatch start;
  const solver::ReconstructionOptions options = arguments.stages.Options();
  if (arguments.chunk == 1) ThrowError("reconstruct", "--chunk", "expected 0 (one process) or at least 2 frames");
  const vision::Dataset dataset(arguments.dataset);
  output::PrepareOutputDirectory(arguments.out, arguments.overwrite, arguments.resume);
  ProgressBar progress;
  const std::string command = arguments.stages.no_refine ? "reconstruct --no-refine" : "reconstruct";
  const output::CommandRun run{command, arguments.out, arguments.overwrite, arguments.resume, InvocationArguments()};
  const auto [first, end] = output::TakeFrames(arguments.dataset, dataset, options.shape);
  if (arguments.chunk > 0 && end - first > arguments.chunk) {
    RunChunkedReconstruct(arguments, dataset, options, run, end - first, start);
    spdlog::info("reconstruct: written to {} in {:.1f} s", arguments.out, start.Seconds());
    return;
  }
  const nlohmann::json stages = output::RunReconstruction(run, dataset, options, arguments.resume, &progress, start);
  spdlog::info("reconstruct: written to {} in {:.1f} s (stages: {})", arguments.out, start.Seconds(), stages.dump());
}

}  // namespace

Command AddReconstructCommand(CLI::App& app) {
  auto arguments = std::make_shared<ReconstructArguments>();
  CLI::App* sub = app.add_subcommand(
      "reconstruct", "Multi-view video → time-varying Loop subdivision surface with scene flow "
                     "(shape init, motion init, spatio-temporal stereo, rigid/non-rigid split)");
  AddDatasetAndOutput(sub, &arguments->dataset, &arguments->out, &arguments->overwrite);
  sub->add_flag("--resume", arguments->resume,
                "Continue an interrupted run in --out: complete stage folders (OUT/stages/) written with the "
                "same options are loaded instead of recomputed");
  sub->add_option("--chunk", arguments->chunk,
                  "A take of more frames runs as chunks of at most this many (subflow plan + run-plan in OUT/plan), "
                  "so memory follows the chunk, not the take; 0 = one process whatever the length")
      ->capture_default_str()->check(CLI::Range(0, 1 << 30));
  AddReconstructionOptions(sub, &arguments->stages);
  return {sub, [arguments] { RunReconstruct(*arguments); }};
}

}  // namespace subflow::cli
