// Running the stages of solver/reconstruction.h with their stage folders
// (output/stage_folder.h, docs/stages.md). The stage commands (`subflow shape`, `motion`,
// `refine`, `retrack`) and `subflow reconstruct` all run a stage through RunStage, and
// `subflow split` and `reconstruct` both finish through WriteReconstruction, so a chain of
// stage commands computes what `reconstruct` computes.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.h"
#include "core/stopwatch.h"
#include "output/report.h"
#include "output/stage_folder.h"
#include "output/stage_frames.h"
#include "solver/reconstruction.h"
#include "vision/dataset.h"

namespace subflow::output {

// The report section of a stage's figures, which is also the key of its options in a
// stage report's "options" and of its time in "timings_seconds": shape_init, motion_init,
// refinement, retrack.
const char* StageSection(solver::Stage stage);
// The stage whose StageName is `name`; throws subflow::Error naming `source` otherwise.
solver::Stage StageNamed(const std::string& name, const std::string& source);

// The "options" of a stage report after the stages of `options` up to `last`: one entry
// per stage section, the options that stage runs with (retrack: RetrackOptions()).
nlohmann::json StageOptionsJson(const solver::ReconstructionOptions& options, solver::Stage last);

// Runs `stage` on `in` (nullptr for the shape stage; the other stages need one), writes
// its stage folder `folder` (which the caller prepared) and returns its record. The
// report: the head of `run`, "stage", and, carried on from in's report and extended by
// this stage, "options" (per stage section), each stage's figures, "timings_seconds" and
// "peak_memory_bytes" (docs/stages.md).
// Without `keep_frames` (the stage commands, which read the record no further), the shape
// stage writes each frame's hull and fit into the folder as it makes them
// (ShapeStageFolderStore) and the record's state holds no frames: its memory does not
// grow with the take. The folder's files are the same either way.
StageRecord RunStage(solver::Stage stage, const CommandRun& run, const vision::Dataset& dataset,
                     const solver::ReconstructionOptions& options, const StageRecord* in, const std::string& folder,
                     Progress* progress = nullptr, bool keep_frames = true);

// The OUTPUT.md result of the final stage's frames and report in run.out (prepared by the
// caller): the split and meshes/, obj/, control/, hull/ frame by frame (WriteSequence),
// base_mesh.ply and report.json (head, `options_json`, every stage's figures from
// `last_report`, rigid_motion, flow, timings; `stages` says per stage whether it was
// computed or loaded). `subflow split` gives the frames of a stage folder
// (StageFolderFrames), so its memory does not grow with the take.
void WriteReconstruction(const CommandRun& run, const vision::Dataset& dataset, const nlohmann::json& options_json,
                         const nlohmann::json& last_report, const StageFrames& last, const nlohmann::json& stages,
                         const Stopwatch& since_start);

// `subflow reconstruct`: the stages of `options` one after another, each writing its
// stage folder <run.out>/stages/<stage>/ as it finishes, then the result in run.out. With
// `resume`, each stage, in order, whose folder is complete and was written for the same
// dataset, options and frames is read instead of run, until the first one that is not:
// that stage and every later one run. Returns {stage name: "computed" | "loaded"}.
nlohmann::json RunReconstruction(const CommandRun& run, const vision::Dataset& dataset,
                                 const solver::ReconstructionOptions& options, bool resume, Progress* progress,
                                 const Stopwatch& since_start);

// The options of every stage from `path`, a JSON object as report.json's "options" of
// reconstruct (subflow plan writes one for its tasks). Throws subflow::Error naming it.
solver::ReconstructionOptions ReadReconstructionOptions(const std::string& path);

// The folder of `stage` inside a reconstruction's output directory: <out>/stages/<name>.
std::string StageFolderOf(const std::string& out, solver::Stage stage);

// `subflow merge`: the stage folders `inputs` (one stage, one connectivity, frame ranges
// that together cover a contiguous range) as one stage folder `folder`. A frame that
// several inputs hold is taken from the one in which it lies farthest from the range's
// ends (a refinement window's edge frames see one side only); on a tie, the earlier input.
// Copies the files frame by frame (memory does not grow with the take). Returns the
// merged report. Throws subflow::Error naming the input that does not fit.
nlohmann::json MergeStageFolders(const CommandRun& run, const std::vector<std::string>& inputs,
                              const std::string& folder);

}  // namespace subflow::output
