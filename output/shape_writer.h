// What `subflow hull` (shape initialization alone) writes into its output directory:
//   hull/<frame>.ply, base_mesh.ply            (result_files.h)
//   control/<frame>/level_<i>.ply              the fitted control meshes of every level
//   meshes/<frame>.ply                         the fitted limit surfaces on one connectivity
//                                              (../shared/OUTPUT.md layout: x y z, vx vy vz)
//   report.json                                command, versions, dataset, options.shape_init,
//                                              shape_init figures, total_seconds
#pragma once

#include <string>

#include "core/stopwatch.h"
#include "output/report.h"
#include "solver/shape/shape_init.h"
#include "vision/dataset.h"

namespace subflow::output {

// run.out must have been prepared (PrepareOutputDirectory).
void WriteShapeResult(const CommandRun& run, const vision::Dataset& dataset,
                      const solver::ShapeInitOptions& options, const solver::ShapeInitResult& result,
                      const Stopwatch& since_start);

}  // namespace subflow::output
