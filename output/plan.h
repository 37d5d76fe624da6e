// A plan: `subflow reconstruct` cut into tasks over chunks of frames, each task one stage
// command on stage folders (docs/stages.md), written to DIR/plan.json for `subflow
// run-plan` (one after another, here) or, with --slurm, as sbatch scripts
// (docs/cluster.md). The tasks:
//   shape             the whole take: per-frame hulls and fits on ONE base connectivity
//                     (the reference frame's), so vertex i is one material point everywhere
//   motion_<c>        per chunk c, chained outwards from the chunk holding the reference
//                     frame: a later chunk starts one frame early, at the last frame of the
//                     chunk before, from that chunk's control points there (--seed), an
//                     earlier chunk likewise backwards; so trajectories continue across
//                     chunk boundaries as the single-process pass propagates them
//   motion_merge      the chunks as one motion stage folder
//   refine_<c>        per chunk c, independent (a job array): the chunk widened by
//                     `overlap` frames on each side, so no chunk frame is refined at a
//                     window's edge
//   refine_merge      each frame from the chunk that holds it most inside
//   retrack_<c>       as motion, chained, on the refined shapes
//   retrack_merge, split   the OUTPUT.md result in DIR/result
// Every task lists its inputs, its output folder, the tasks it depends on and its stamp
// (StampTasks); a task is finished when its output folder holds report.json (written
// last) and the stamp of the plan it was run for equals its stamp in this plan.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "solver/reconstruction.h"
#include "vision/dataset.h"

namespace subflow::output {

// 2: tasks carry a "stamp" (plans of version 1 do not; plan them again with --overwrite).
inline constexpr int kPlanVersion = 2;

// The file in a task's output folder holding the stamp of the task it was run for.
inline constexpr const char* kTaskStampFile = "task_stamp.json";

struct PlanOptions {
  int chunk = 24;    // frames per chunk (≥ 2)
  int overlap = 2;   // frames a refinement chunk reaches into each neighbour (≥ 0)
  bool slurm = false;
  // Memory requested per Slurm task (MiB); 0 = from the task's measured peak (a finished
  // run-plan of the same plan records it) × 1.5, else kDefaultTaskMemoryMiB.
  int memory_mib = 0;

  void Check() const;  // throws subflow::Error naming the field
};

inline constexpr int kDefaultTaskMemoryMiB = 4096;

// Builds the plan of `options` on `dataset` for the directory `directory` (absolute paths
// in the task arguments) and writes directory/plan.json and directory/options.json (the
// options every task reads: --options); with options.slurm, also directory/slurm/.
// When `directory` holds a plan already, CheckReplan(directory, plan, overwrite) decides
// first. `arguments`: the command line of `subflow plan`, recorded in plan.json. Returns
// the plan.
nlohmann::json WritePlan(const std::string& dataset_directory, const vision::Dataset& dataset,
                         const solver::ReconstructionOptions& options, const PlanOptions& plan_options,
                         const std::string& directory, bool overwrite,
                         const nlohmann::json& arguments = nlohmann::json::object());

// The dataset frames [first, end) that `options` reconstruct (shape.first_frame,
// shape.frame_count; −1 = to the end); throws subflow::Error naming the dataset when none.
std::pair<int, int> TakeFrames(const std::string& dataset_path, const vision::Dataset& dataset,
                               const solver::ShapeInitOptions& options);

// `subflow reconstruct` of a take longer than its --chunk, after run-plan's tasks of the
// plan `plan` (in out/plan) finished: moves the result (PLAN/result, OUTPUT.md) into `out`
// and writes out/report.json: the split task's report with `head` (ReportHead: command,
// arguments, output, ...) over it, "plan" (chunk, overlap, chunks, `tasks`: what
// RunPlanTasks returned) and "timings_seconds" per stage summed over the tasks (a skipped
// task counts with the time its earlier run recorded) with "total" = `total_seconds` (this
// run's). The split task's folder stops being finished before the first file moves;
// report.json is written last.
void AdoptPlanResult(const nlohmann::json& plan, const nlohmann::json& tasks, const std::string& out,
                     nlohmann::json head, double total_seconds);

// Reads directory/plan.json; throws subflow::Error naming it.
nlohmann::json ReadPlan(const std::string& directory);

// Gives every task of `tasks` (in an order where a task follows those it depends on) its
// "stamp": a 64-bit fingerprint of its definition, the canonical JSON (sorted keys) of
//   argv         the command line (dataset, frames, input and output folders, seed)
//   options      options_read[i]: the options the task reads from options.json (a stage
//                task: every stage's options up to its own, as its stage report records
//                them; null for merge and split, which read none)
//   dataset      `dataset` (output::DatasetJson: directory, frames, cameras, bounds, …)
//   depends_on   {id: stamp} of the tasks it depends on,
// so a task's stamp changes with anything upstream of it, transitively.
void StampTasks(nlohmann::json* tasks, const std::vector<nlohmann::json>& options_read, const nlohmann::json& dataset);

// Whether task `task` of a plan is finished: its output holds report.json
// and kTaskStampFile with the task's stamp (a folder left by another plan is not).
bool TaskFinished(const nlohmann::json& task);
// Removes the stamp in task's output folder (before the task runs again).
void ForgetTaskFinished(const nlohmann::json& task);
// Writes task's stamp into its output folder (after the task succeeded).
void RecordTaskFinished(const nlohmann::json& task);

// Planning `plan` into `directory` when it holds a plan already: returns when that plan
// has the same tasks with the same stamps (nothing of its results changes meaning) or
// when `overwrite` is set (then a finished task whose stamp is unchanged stays finished and
// the others run again, as TaskFinished sees it). Otherwise throws subflow::Error naming
// the directory and the tasks defined otherwise, added or no longer planned.
void CheckReplan(const std::string& directory, const nlohmann::json& plan, bool overwrite);

// Writes directory/slurm/: one sbatch script per stage phase (job arrays for the refine
// chunks), --dependency=afterok between them, and submit.sh that submits them in order.
void WriteSlurmScripts(const std::string& directory, const nlohmann::json& plan, int memory_mib);

}  // namespace subflow::output
