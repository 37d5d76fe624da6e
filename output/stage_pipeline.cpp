#include "output/stage_pipeline.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/memory.h"
#include "output/options_json.h"
#include "output/result_files.h"
#include "output/result_writer.h"
#include "output/sequence_writer.h"

namespace subflow::output {

namespace fs = std::filesystem;
using solver::Stage;

namespace {

constexpr Stage kStages[] = {Stage::kShape, Stage::kMotion, Stage::kRefine, Stage::kRetrack};

nlohmann::json OptionsOf(const solver::ReconstructionOptions& options, Stage stage) {
  switch (stage) {
    case Stage::kShape: return options.shape;
    case Stage::kMotion: return options.motion;
    case Stage::kRefine: return options.refinement;
    case Stage::kRetrack: return options.RetrackOptions();
  }
  return nullptr;
}

// Frames where a quarter of the refined surface stays out of the retrack's reach
// (solver::kLostTargetFraction, after the retrack's registration): the chain has left the
// refined shapes there (docs/shape.md, "The retrack on a take with large motion" and "The
// retrack registers the frames that lost their refined surface"). The motion
// stage's targets, the per-frame hull fits, hold clutter on real takes (the shared pose2sim
// take: over a quarter in 90 of 100 frames), so there the figure is only reported.
void WarnRetrackOffTarget(const solver::MotionInitResult& figures, int first_frame) {
  const std::vector<int> off = figures.FramesOffTarget(solver::kLostTargetFraction);
  if (off.empty()) return;
  double most = 0.0;
  for (const solver::MotionFrameReport& frame : figures.frames) most = std::max(most, frame.correction_unreached);
  const std::string frames = off.size() == 1 ? std::to_string(first_frame + off.front())
                                             : fmt::format("{}–{}", first_frame + off.front(), first_frame + off.back());
  spdlog::warn(
      "retrack: in {} of {} frames ({}) more than {:.0f} % of the surface is out of the correction's reach of the "
      "frame's refined surface (up to {:.0f} %; report.json: retrack.frames[].correction_unreached): the tracked "
      "surface left it there, e.g. a limb far from the reference frame (the refine stage's own surfaces, with a "
      "poorer flow: `subflow split DATASET --from <refine stage folder> --out R`)",
      off.size(), figures.frames.size(), frames, 100 * solver::kLostTargetFraction, 100 * most);
}

// Runs the solver stage and returns its state; *section gets its figures for the report.
solver::StageState RunSolverStage(Stage stage, const vision::Dataset& dataset,
                                  const solver::ReconstructionOptions& options, const StageRecord* in,
                                  Progress* progress, nlohmann::json* section, std::string* brief,
                                  std::vector<std::vector<geometry::Positions>>* all_levels,
                                  solver::ShapeFrameStore* store) {
  if (stage == Stage::kShape) {
    solver::ShapeInitResult figures;
    solver::StageState state = solver::RunShapeStage(dataset, options.shape, progress, &figures, store);
    *section = ShapeInitJson(dataset, options.shape, figures);
    *brief = figures.BriefReport();
    // Moved, not copied: the figures go when this returns, the levels are written next.
    for (solver::FrameShapeInit& frame : figures.frames) all_levels->push_back(std::move(frame.control));
    return state;
  }
  if (!in) ThrowError(StageName(stage), "input", "the stage needs the folder of the stage before it");
  if (stage == Stage::kRefine) {
    solver::RefinementResult figures;
    solver::StageState state = solver::RunRefineStage(dataset, in->state, options.refinement, progress, &figures);
    *section = RefinementJson(options.refinement, figures, state.first_frame);
    *brief = figures.BriefReport();
    return state;
  }
  const solver::MotionInitOptions motion = stage == Stage::kMotion ? options.motion : options.RetrackOptions();
  solver::MotionInitResult figures;
  solver::StageState state = solver::RunMotionStage(dataset, in->state, motion, progress, &figures);
  *section = MotionInitJson(motion, figures, state.first_frame);
  *brief = (stage == Stage::kRetrack ? "retrack: " : "") + figures.BriefReport();
  if (stage == Stage::kRetrack) WarnRetrackOffTarget(figures, state.first_frame);
  return state;
}

}  // namespace

const char* StageSection(Stage stage) {
  switch (stage) {
    case Stage::kShape: return "shape_init";
    case Stage::kMotion: return "motion_init";
    case Stage::kRefine: return "refinement";
    case Stage::kRetrack: return "retrack";
  }
  return "?";
}

Stage StageNamed(const std::string& name, const std::string& source) {
  for (Stage stage : kStages)
    if (name == StageName(stage)) return stage;
  ThrowError(source, "stage", "\"" + name + "\" is not one of shape, motion, refine, retrack");
}

nlohmann::json StageOptionsJson(const solver::ReconstructionOptions& options, Stage last) {
  nlohmann::json json = nlohmann::json::object();
  for (Stage stage : solver::StagesOf(options)) {
    json[StageSection(stage)] = OptionsOf(options, stage);
    if (stage == last) break;
  }
  return json;
}

StageRecord RunStage(Stage stage, const CommandRun& run, const vision::Dataset& dataset,
                     const solver::ReconstructionOptions& options, const StageRecord* in, const std::string& folder,
                     Progress* progress, bool keep_frames) {
  const Stopwatch start;
  StageRecord record;
  nlohmann::json section;
  std::string brief;
  std::vector<std::vector<geometry::Positions>> all_levels;
  // The shape stage without keep_frames writes its frames into the folder as it makes them.
  std::optional<ShapeStageFolderStore> store;
  if (stage == Stage::kShape && !keep_frames) store.emplace(folder);
  record.state = RunSolverStage(stage, dataset, options, in, progress, &section, &brief, &all_levels,
                                store ? &*store : nullptr);
  const double seconds = start.Seconds();
  spdlog::info("{}", brief);

  nlohmann::json& report = record.report;
  report = ReportHead(run, dataset);
  report["stage"] = StageName(stage);
  report["options"] = nlohmann::json::object();
  report["timings_seconds"] = nlohmann::json::object();
  report["peak_memory_bytes"] = nlohmann::json::object();
  if (in) {  // what the stages before this one ran with and found
    for (const char* key : {"options", "timings_seconds", "peak_memory_bytes"})
      if (in->report.contains(key)) report[key] = in->report[key];
    for (Stage before : kStages)
      if (in->report.contains(StageSection(before))) report[StageSection(before)] = in->report[StageSection(before)];
    if (in->report.contains("seed") && stage != Stage::kRefine) report["seed"] = in->report["seed"];
    if (in->report.contains("take_reference_frame")) report["take_reference_frame"] = in->report["take_reference_frame"];
  }
  report["options"][StageSection(stage)] = OptionsOf(options, stage);
  report[StageSection(stage)] = section;
  report["timings_seconds"][StageSection(stage)] = seconds;
  report["peak_memory_bytes"][StageSection(stage)] = PeakResidentBytes();
  if (store)
    FinishShapeStageFolder(folder, record, store->frames_fitted());
  else
    WriteStageFolder(folder, record, all_levels.empty() ? nullptr : &all_levels);
  return record;
}

void WriteReconstruction(const CommandRun& run, const vision::Dataset& dataset, const nlohmann::json& options_json,
                         const nlohmann::json& last_report, const StageFrames& last, const nlohmann::json& stages,
                         const Stopwatch& since_start) {
  const Stopwatch write_start;
  nlohmann::json report = ReportHead(run, dataset);
  report["options"] = options_json;
  report["stages"] = stages;
  for (Stage stage : kStages)
    if (last_report.contains(StageSection(stage))) report[StageSection(stage)] = last_report[StageSection(stage)];
  solver::RigidSplit split;
  report["flow"] = WriteSequence(run.out, last, &split);
  report["rigid_motion"] = RigidMotionJson(split.rigid, last.first_frame());
  WriteHullFiles(run.out, last.BaseMesh(), last.first_frame(), {});  // base_mesh.ply (hull/: WriteSequence)
  nlohmann::json timings = last_report.value("timings_seconds", nlohmann::json::object());
  timings["rigid_split"] = split.seconds;
  timings["writing"] = write_start.Seconds() - split.seconds;
  timings["total"] = since_start.Seconds();
  report["timings_seconds"] = timings;
  report["total_seconds"] = timings["total"];
  nlohmann::json memory = last_report.value("peak_memory_bytes", nlohmann::json::object());
  memory["writing"] = PeakResidentBytes();
  report["peak_memory_bytes"] = memory;
  WriteJsonFile((fs::path(run.out) / "report.json").string(), report);
  spdlog::info("{}", split.BriefReport());
}

solver::ReconstructionOptions ReadReconstructionOptions(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path, "the options of every stage (report.json's \"options\")");
  try {
    solver::ReconstructionOptions options = json.get<solver::ReconstructionOptions>();
    options.Check();
    return options;
  } catch (const nlohmann::json::exception& e) {
    ThrowError(path, "options", std::string("expected every stage's options as report.json records them (") +
                                    e.what() + ")");
  }
}

std::string StageFolderOf(const std::string& out, Stage stage) {
  return (fs::path(out) / "stages" / StageName(stage)).string();
}

namespace {

// Whether the complete stage folder `folder` was written by `stage` for this dataset, these
// options and, after the shape stage, the frames of `in`.
bool StageMatches(const std::string& folder, Stage stage, const vision::Dataset& dataset,
                  const solver::ReconstructionOptions& options, const StageRecord* in) {
  if (!StageFolderComplete(folder)) return false;
  const nlohmann::json report =
      ReadJsonFile((fs::path(folder) / "report.json").string(), "a stage report (docs/stages.md)");
  const bool same_frames =
      !in || report.value("frames", nlohmann::json()) ==
                 nlohmann::json{{"first", in->state.first_frame}, {"count", in->state.frame_count()}};
  return report.value("stage_layout_version", -1) == kStageLayoutVersion &&
         report.value("stage", "") == StageName(stage) && same_frames &&
         report.value("options", nlohmann::json()) == StageOptionsJson(options, stage) && report.contains("dataset") &&
         report["dataset"].value("directory", "") == DatasetJson(dataset)["directory"];
}

}  // namespace

nlohmann::json RunReconstruction(const CommandRun& run, const vision::Dataset& dataset,
                                 const solver::ReconstructionOptions& options, bool resume, Progress* progress,
                                 const Stopwatch& since_start) {
  std::optional<StageRecord> last;
  nlohmann::json stages = nlohmann::json::object();
  bool reuse = resume;
  for (Stage stage : solver::StagesOf(options)) {
    const std::string folder = StageFolderOf(run.out, stage);
    const StageRecord* in = last ? &*last : nullptr;
    reuse = reuse && StageMatches(folder, stage, dataset, options, in);
    if (reuse) {
      last = ReadStageFolder(folder, StageName(stage));
      spdlog::info("{}: loaded from {} (--resume)", StageName(stage), folder);
    } else {
      last = RunStage(stage, run, dataset, options, in, folder, progress);
    }
    stages[StageName(stage)] = reuse ? "loaded" : "computed";
    ReleaseFreeMemory();  // the stage's freed blocks: the next one allocates other sizes
  }
  WriteReconstruction(run, dataset, options, last->report, StateFrames(last->state), stages, since_start);
  return stages;
}

}  // namespace subflow::output
