// report.json sections shared by the subcommands: what was run (dataset, options,
// versions) and the figures of each stage.
#pragma once

#include <nlohmann/json.hpp>

#include "solver/shape/shape_init.h"
#include "vision/dataset.h"

namespace subflow::cli {

// {"subflow_version", "libraries": {...}}.
nlohmann::json VersionsJson();
// {"directory", "cameras", "frames", "bounds", "has_masks", ...}.
nlohmann::json DatasetJson(const vision::Dataset& dataset);
// Every field of the silhouette and voxel-carving options (what report.json records of
// them; automatic values are recorded as given, e.g. −1, with the values used per frame).
nlohmann::json SilhouetteOptionsJson(const vision::SilhouetteOptions& options);
nlohmann::json VoxelCarvingOptionsJson(const vision::VoxelCarvingOptions& options);
// The options of shape initialization, field by field.
nlohmann::json ShapeInitOptionsJson(const solver::ShapeInitOptions& options);
// Options, base mesh, hierarchy and per-frame figures of shape initialization.
nlohmann::json ShapeInitReport(const vision::Dataset& dataset, const solver::ShapeInitOptions& options,
                               const solver::ShapeInitResult& result);

}  // namespace subflow::cli
