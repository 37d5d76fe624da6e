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
// Every task lists its inputs, its output folder and the tasks it depends on; a task is
// finished when its output folder holds report.json (written last).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "solver/reconstruction.h"
#include "vision/dataset.h"

namespace subflow::output {

inline constexpr int kPlanVersion = 1;

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
// `arguments`: the command line of `subflow plan`, recorded in plan.json. Returns the plan.
nlohmann::json WritePlan(const std::string& dataset_directory, const vision::Dataset& dataset,
                         const solver::ReconstructionOptions& options, const PlanOptions& plan_options,
                         const std::string& directory, const nlohmann::json& arguments = nlohmann::json::object());

// Reads directory/plan.json; throws subflow::Error naming it.
nlohmann::json ReadPlan(const std::string& directory);

// Whether task `task` of a plan in `directory` is finished (its output holds report.json).
bool TaskFinished(const std::string& directory, const nlohmann::json& task);

// Writes directory/slurm/: one sbatch script per stage phase (job arrays for the refine
// chunks), --dependency=afterok between them, and submit.sh that submits them in order.
void WriteSlurmScripts(const std::string& directory, const nlohmann::json& plan, int memory_mib);

}  // namespace subflow::output
