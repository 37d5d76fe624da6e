// report.json, section by section: what was run (the command, versions, the dataset, every
// option: output/options_json.h) and the figures of each stage, as `subflow` writes them.
// Frames are dataset frames (a stage's own frame indices plus its first frame).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "solver/motion/motion_init.h"
#include "solver/rigid/rigid_motion.h"
#include "solver/shape/shape_init.h"
#include "solver/stereo/stereo_refinement.h"
#include "vision/dataset.h"

namespace subflow::output {

// {"subflow", "libraries": {...}}.
nlohmann::json VersionsJson();
// {"directory", "frames", "cameras", "bounds", "has_masks", ...}.
nlohmann::json DatasetJson(const vision::Dataset& dataset);
// What the user asked for: the subcommand (with the flags that change what it runs, e.g.
// "reconstruct --no-refine"), the output directory and whether it could overwrite.
struct CommandRun {
  std::string command;
  std::string out;
  bool overwrite = false;
  bool resume = false;  // reconstruct --resume
  nlohmann::json arguments = nlohmann::json::object();  // the command line (cli::ArgumentsJson)
};

// {"command", "arguments", "output", "overwrite", "resume", "versions", "dataset"}: the head
// of every report.
nlohmann::json ReportHead(const CommandRun& run, const vision::Dataset& dataset);

// Figures of shape initialization: reference frame, base mesh, levels, the backgrounds
// estimated from the video (with the settings they were estimated with), per frame.
nlohmann::json ShapeInitJson(const vision::Dataset& dataset, const solver::ShapeInitOptions& options,
                             const solver::ShapeInitResult& result);
// {"options", "reference_frame", "frames", "seconds"} of one motion pass.
nlohmann::json MotionInitJson(const solver::MotionInitOptions& options, const solver::MotionInitResult& result,
                              int first_frame);
// {"options", "levels", "frames", "seconds"} of the refinement.
nlohmann::json RefinementJson(const solver::StereoRefinementOptions& options,
                              const solver::RefinementResult& result, int first_frame);
// One entry per frame step: v, ω, rotation angle, fit residual.
nlohmann::json RigidMotionJson(const std::vector<solver::RigidMotion>& rigid, int first_frame);

}  // namespace subflow::output
