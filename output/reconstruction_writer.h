// Everything `subflow reconstruct` writes into its output directory: the sequence
// (sequence_writer.h: meshes/, obj/, control/), the visual hulls and the base mesh
// (result_files.h: hull/, base_mesh.ply) and report.json — the command, versions, dataset,
// every option (options_json.h), each stage's figures (report.h: shape_init, motion_init,
// refinement, retrack with the options each pass ran with), rigid_motion, flow and the
// timings.
#pragma once

#include <string>

#include "core/stopwatch.h"
#include "output/report.h"
#include "solver/reconstruction.h"
#include "vision/dataset.h"

namespace subflow::output {

// run.out must have been prepared (PrepareOutputDirectory). `since_start` times the whole
// command (report.json's total_seconds).
void WriteReconstruction(const CommandRun& run, const vision::Dataset& dataset,
                         const solver::ReconstructionOptions& options, const solver::ReconstructionResult& result,
                         const Stopwatch& since_start);

}  // namespace subflow::output
