// The stages of `subflow reconstruct` as commands on stage folders (docs/stages.md):
//   subflow shape   DATASET --out S [--frames A:B] [shape options]     (also: hull)
//   subflow motion  DATASET --from S --out M [--frames A:B] [motion options]
//   subflow refine  DATASET --from M --out R [--frames A:B] [refinement options]
//   subflow retrack DATASET --from R --out T [--frames A:B] [motion options, --retrack-weight, --retrack-highpass, --no-retrack-register]
//   subflow split   DATASET --from T --out RESULT                      (the OUTPUT.md result)
//   subflow merge   FOLDER... --out DIR     (stage folders of frame ranges → one)
// Each runs output::RunStage, as reconstruct does.
#include <memory>
#include <optional>

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

struct StageArguments {
  std::string dataset;
  std::string from;  // the previous stage's folder (not for shape)
  std::string seed;  // motion, retrack: the stage folder whose trajectories this range continues
  std::string options_file;  // --options: every stage's options from a JSON file
  std::string out;
  bool overwrite = false;
  std::string evidence = "auto";
  int first_frame = 0, frame_count = -1;  // --frames of the input (not for shape)
  solver::ReconstructionOptions options;
};

// The stage whose folder `stage` reads.
solver::Stage InputStage(solver::Stage stage) {
  switch (stage) {
    case solver::Stage::kMotion: return solver::Stage::kShape;
    case solver::Stage::kRefine: return solver::Stage::kMotion;
    default: return solver::Stage::kRefine;
  }
}

// Checks the options `stage` runs with (before any input is read).
void CheckStageOptions(solver::Stage stage, const solver::ReconstructionOptions& options) {
  switch (stage) {
    case solver::Stage::kShape: return options.shape.Check();
    case solver::Stage::kMotion: return options.motion.Check();
    case solver::Stage::kRefine: return options.refinement.Check();
    case solver::Stage::kRetrack: return options.Check();
  }
}

void RunStageCommand(solver::Stage stage, const std::string& name, const StageArguments& arguments) {
  solver::ReconstructionOptions options = arguments.options;
  options.shape.silhouettes.source = vision::ParseEvidenceSource(arguments.evidence, "--evidence");
  if (!arguments.options_file.empty()) options = output::ReadReconstructionOptions(arguments.options_file);
  CheckStageOptions(stage, options);
  const vision::Dataset dataset(arguments.dataset);
  std::optional<output::StageRecord> in;
  if (stage != solver::Stage::kShape) {
    in = output::ReadStageFolder(arguments.from, solver::StageName(InputStage(stage)), arguments.first_frame,
                                 arguments.frame_count);
    if (!arguments.seed.empty()) output::SeedStageInput(&*in, arguments.seed);
  }
  output::PrepareOutputDirectory(arguments.out, arguments.overwrite);
  ProgressBar progress;
  const output::CommandRun run{name, arguments.out, arguments.overwrite, false, InvocationArguments()};
  // keep_frames false: the shape stage streams its frames to the folder (docs/cluster.md).
  output::RunStage(stage, run, dataset, options, in ? &*in : nullptr, arguments.out, &progress, false);
  spdlog::info("{}: stage folder written to {}", name, arguments.out);
}

// `name`: the subcommand, StageName(stage) or an alias (hull).
Command AddStageCommand(CLI::App& app, solver::Stage stage, const std::string& name, const std::string& description) {
  auto arguments = std::make_shared<StageArguments>();
  CLI::App* sub = app.add_subcommand(name, description);
  AddDatasetAndOutput(sub, &arguments->dataset, &arguments->out, &arguments->overwrite);
  if (stage != solver::Stage::kShape) {
    sub->add_option("--from", arguments->from, "Stage folder of the previous stage")
        ->required()->check(CLI::ExistingDirectory);
    AddFramesOption(sub, &arguments->first_frame, &arguments->frame_count, false);
  }
  sub->add_option("--options", arguments->options_file,
                  "Every stage's options from a JSON file (as report.json's \"options\" of reconstruct; "
                  "subflow plan writes one), instead of the flags")
      ->check(CLI::ExistingFile);
  if (stage == solver::Stage::kMotion || stage == solver::Stage::kRetrack)
    sub->add_option("--seed", arguments->seed,
                    "Stage folder (of this stage, an earlier range) whose trajectories this range continues: the "
                    "frame both hold becomes the reference frame, with the seed's control points")
        ->check(CLI::ExistingDirectory);
  switch (stage) {
    case solver::Stage::kShape:
      AddShapeInitOptions(sub, &arguments->options.shape, &arguments->evidence);
      break;
    case solver::Stage::kRetrack:
      AddRetrackOptions(sub, &arguments->options);
      AddMotionInitOptions(sub, &arguments->options.motion, false);
      break;
    case solver::Stage::kMotion:
      AddMotionInitOptions(sub, &arguments->options.motion, true);
      break;
    case solver::Stage::kRefine:
      AddRefinementOptions(sub, &arguments->options.refinement);
      break;
  }
  return {sub, [stage, name, arguments] { RunStageCommand(stage, name, *arguments); }};
}

struct SplitArguments {
  std::string dataset, from, out;
  bool overwrite = false;
};

void RunSplit(const SplitArguments& arguments) {
  const Stopwatch start;
  const vision::Dataset dataset(arguments.dataset);
  // Frame by frame from the folder: memory does not grow with the take (docs/cluster.md).
  const output::StageFolderFrames last(arguments.from);
  output::PrepareOutputDirectory(arguments.out, arguments.overwrite);
  // A named copy: items() of the temporary value() returns would dangle in the loop.
  const nlohmann::json options = last.report().value("options", nlohmann::json::object());
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [section, ignored] : options.items()) stages[section] = "loaded";
  const output::CommandRun run{"split", arguments.out, arguments.overwrite, false, InvocationArguments()};
  output::WriteReconstruction(run, dataset, options, last.report(), last, stages, start);
  spdlog::info("split: {} frames written to {} in {:.1f} s", last.frame_count(), arguments.out, start.Seconds());
}

struct MergeArguments {
  std::vector<std::string> inputs;
  std::string out;
  bool overwrite = false;
};

void RunMerge(const MergeArguments& arguments) {
  output::PrepareOutputDirectory(arguments.out, arguments.overwrite);
  const output::CommandRun run{"merge", arguments.out, arguments.overwrite, false, InvocationArguments()};
  const nlohmann::json merged = output::MergeStageFolders(run, arguments.inputs, arguments.out);
  spdlog::info("merge: {} stage folders, frames {}, written to {}", arguments.inputs.size(), merged["frames"].dump(),
               arguments.out);
}

}  // namespace

Command AddShapeCommand(CLI::App& app) {
  return AddStageCommand(app, solver::Stage::kShape, "shape",
                         "Shape initialization (method §4.1): visual hull per frame, base mesh, and a subdivision "
                         "surface fitted to every frame on one connectivity; writes a stage folder");
}
Command AddHullCommand(CLI::App& app) {
  return AddStageCommand(app, solver::Stage::kShape, "hull", "The shape stage under its earlier name (= shape)");
}
Command AddMotionCommand(CLI::App& app) {
  return AddStageCommand(app, solver::Stage::kMotion, "motion",
                         "Motion initialization (§4.2) on a shape stage folder: trajectories by normal flow");
}
Command AddRefineCommand(CLI::App& app) {
  return AddStageCommand(app, solver::Stage::kRefine, "refine",
                         "Spatio-temporal stereo refinement (§4.3) on a motion stage folder");
}
Command AddRetrackCommand(CLI::App& app) {
  return AddStageCommand(app, solver::Stage::kRetrack, "retrack",
                         "The motion pass again, on a refine stage folder's refined shapes");
}

Command AddSplitCommand(CLI::App& app) {
  auto arguments = std::make_shared<SplitArguments>();
  CLI::App* sub = app.add_subcommand(
      "split", "Rigid / non-rigid split (§5) of a stage folder's trajectories; writes the result (OUTPUT.md)");
  AddDatasetAndOutput(sub, &arguments->dataset, &arguments->out, &arguments->overwrite);
  sub->add_option("--from", arguments->from, "Stage folder of the last stage run (retrack, refine or motion)")
      ->required()->check(CLI::ExistingDirectory);
  return {sub, [arguments] { RunSplit(*arguments); }};
}

Command AddMergeCommand(CLI::App& app) {
  auto arguments = std::make_shared<MergeArguments>();
  CLI::App* sub = app.add_subcommand(
      "merge", "Stage folders of one stage over ranges of frames (--frames) → one stage folder over all of them");
  sub->add_option("FOLDERS", arguments->inputs, "Stage folders, one per range")
      ->required()->check(CLI::ExistingDirectory);
  sub->add_option("--out", arguments->out, "Output stage folder (must be new or empty)")->required();
  sub->add_flag("--overwrite", arguments->overwrite, "Write into a non-empty output directory");
  return {sub, [arguments] { RunMerge(*arguments); }};
}

}  // namespace subflow::cli
