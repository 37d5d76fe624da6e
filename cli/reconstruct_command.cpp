// `subflow reconstruct DATASET --out DIR`: the product's main job, start to finish —
// shape initialization → motion initialization → stereo refinement (unless --no-refine)
// → re-tracking → rigid / non-rigid split (output/stage_pipeline.h: the stages of the
// stage commands, each writing its stage folder DIR/stages/<stage>/; --resume reuses the
// complete ones of an interrupted run).
#include <memory>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "cli/stage_options.h"
#include "core/stopwatch.h"
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
  ReconstructionArguments stages;
};

void RunReconstruct(const ReconstructArguments& arguments) {
  const Stopwatch start;
  const solver::ReconstructionOptions options = arguments.stages.Options();
  const vision::Dataset dataset(arguments.dataset);
  output::PrepareOutputDirectory(arguments.out, arguments.overwrite, arguments.resume);
  ProgressBar progress;
  const std::string command = arguments.stages.no_refine ? "reconstruct --no-refine" : "reconstruct";
  const output::CommandRun run{command, arguments.out, arguments.overwrite, arguments.resume, InvocationArguments()};
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
  AddReconstructionOptions(sub, &arguments->stages);
  return {sub, [arguments] { RunReconstruct(*arguments); }};
}

}  // namespace subflow::cli
