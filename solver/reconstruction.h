// The product's main job (method §4): shape initialization → motion initialization →
// spatio-temporal stereo refinement → rigid / non-rigid split, on one LoopHierarchy for
// the whole sequence. The result is the finest control points of every frame; the output
// surface is their limit surface at the finest level's vertices (the same vertices and
// faces at every frame, so each vertex is a trajectory).
#pragma once

#include <optional>
#include <vector>

#include "geometry/loop_hierarchy.h"
#include "geometry/multires_shape.h"
#include "core/progress.h"
#include "solver/motion_init.h"
#include "solver/rigid_motion.h"
#include "solver/shape_init.h"
#include "solver/stereo_refinement.h"
#include "vision/dataset.h"

namespace subflow::solver {

struct ReconstructionOptions {
  ShapeInitOptions shape;
  MotionInitOptions motion;
  StereoRefinementOptions refinement;
  bool refine = true;  // false: stop after motion initialization (--no-refine)
  // After refinement, re-estimate the trajectories by normal flow on the refined shapes
  // (motion initialization again, each frame's normal component snapped to its refined
  // surface with weight `retrack_weight`): the first pass estimated the image motion on
  // the visual hulls, whose points project to the wrong pixels wherever the hull is off.
  bool retrack = true;
  // Weight 1 passes each frame's shape noise straight into the flow. On the blob (24
  // frames), mean end-point error / accuracy P90: 0.5 → 0.081 / 0.559 mm, 0.25 → 0.062 /
  // 0.543 mm (frames 10–12: 1.0 → 0.090 mm, 0.5 → 0.064 mm at the same accuracy).
  double retrack_weight = 0.25;

  void Check() const;  // throws subflow::Error naming the field
};

struct ReconstructionResult {
  ShapeInitResult shape;
  MotionInitResult motion;
  std::optional<RefinementResult> refinement;
  std::optional<MotionInitResult> retrack;  // the second motion pass, when run
  int first_frame = 0;
  std::vector<geometry::Positions> control;  // final finest control points per frame
  geometry::Trajectory trajectory;           // their multires analysis
  std::vector<RigidMotion> rigid;            // per frame step, fitted on the base c⁰
  double shape_seconds = 0, motion_seconds = 0, refinement_seconds = 0, retrack_seconds = 0,
         analysis_seconds = 0;

  const geometry::LoopHierarchy& hierarchy() const { return *shape.hierarchy; }
  // The output surface of frame i (0-based within the processed frames): the limit
  // positions of the finest level's vertices.
  geometry::Positions Surface(int i) const;
};

// The silhouettes the refinement keeps the outline on: the dataset's masks when it has
// them (undistorted), else the visual hulls of shape initialization rendered into each
// camera. Frames are indices within the processed range.
RefinementImageLoader SilhouetteLoader(const vision::Dataset& dataset, const ShapeInitResult& shape);

ReconstructionResult Reconstruct(const vision::Dataset& dataset, const ReconstructionOptions& options,
                                 Progress* progress = nullptr);

}  // namespace subflow::solver
