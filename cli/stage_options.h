// Command-line options of the pipeline stages, shared by the subcommands that run them.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "solver/motion/motion_init.h"
#include "solver/reconstruction.h"
#include "solver/shape/shape_init.h"
#include "solver/stereo/stereo_refinement.h"

namespace subflow::cli {

// DATASET (an existing directory), --out (required) and --overwrite: the arguments of every
// subcommand that reads a dataset and writes a result directory.
void AddDatasetAndOutput(CLI::App* app, std::string* dataset, std::string* out, bool* overwrite);

// --frames A:B (dataset frames A..B−1: *first = A, *count = B − A), or, with
// `allow_count`, --frames N (*count = N, −1 = to the end; *first unchanged).
void AddFramesOption(CLI::App* app, int* first, int* count, bool allow_count);

// --evidence, --levels, --base-faces, --reference-frame, --first-frame, --frames,
// --resolution, --min-cameras, --max-misses, --evidence-threshold, --footprint-margin,
// --lambda, --motion-window, --motion-threshold, --background-threshold (out-of-range values
// are rejected naming the flag).
void AddShapeInitOptions(CLI::App* app, solver::ShapeInitOptions* options, std::string* evidence);

// --motion-smoothness, and with `first_pass` --motion-highpass and --hull-weight (the
// retrack has its own: AddRetrackOptions).
void AddMotionInitOptions(CLI::App* app, solver::MotionInitOptions* options, bool first_pass = true);

// --retrack-weight, --retrack-highpass.
void AddRetrackOptions(CLI::App* app, solver::ReconstructionOptions* options);

// --refine-from, --refine-to, --window, --window-overlap, --rounds, --iterations,
// --linear-solver, --threads, --samples-per-pixel, --max-cameras and the term weights.
void AddRefinementOptions(CLI::App* app, solver::StereoRefinementOptions* options);

// What `reconstruct` (and `plan`) run, as the command line gives it.
struct ReconstructionArguments {
  solver::ReconstructionOptions options;
  std::string evidence = "auto";
  bool no_refine = false;

  // `options` with --evidence and --no-refine applied, checked (throws subflow::Error).
  solver::ReconstructionOptions Options() const;
};

// --no-refine, --no-retrack, --retrack-weight, --retrack-highpass and the options of every stage.
void AddReconstructionOptions(CLI::App* app, ReconstructionArguments* arguments);

}  // namespace subflow::cli
