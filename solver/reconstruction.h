// The product's main job (method §4): shape initialization → motion initialization →
// spatio-temporal stereo refinement → rigid / non-rigid split, on one LoopHierarchy for
// the whole sequence. The result is the finest control points of every frame; the output
// surface is their limit surface at the finest level's vertices (the same vertices and
// faces at every frame, so each vertex is a trajectory).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/progress.h"
#include "geometry/loop_hierarchy.h"
#include "solver/motion/motion_init.h"
#include "solver/rigid/rigid_split.h"
#include "solver/shape/shape_init.h"
#include "solver/stereo/stereo_refinement.h"
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
  // Motion initialization and stereo refinement see every camera's images reduced so
  // that the finest level's edges of the reference frame's fitted surface project to
  // about this many pixels (vision/working_scale.h: SurfaceScale; never enlarged): finer
  // images hold detail the surface cannot represent and cost time in proportion to
  // their pixels. The scenes the accuracy floors were measured on have median finest
  // edges of 1.0–2.0 px (../shared/data/blob 2.0, bust_front 1.7–2.0, take_small 1.4–1.5)
  // and are left at their size; the 1088×1920 pose2sim take (8–11 px) is reduced to
  // about a third. 0 = the stored size.
  double image_edge_pixels = 3.0;

  void Check() const;  // throws subflow::Error naming the field
  // The options of the second motion pass: `motion` with hull_weight = retrack_weight.
  MotionInitOptions RetrackOptions() const;
};

struct ReconstructionResult {
  ShapeInitResult shape;
  MotionInitResult motion;
  std::optional<RefinementResult> refinement;
  std::optional<MotionInitResult> retrack;  // the second motion pass, when run
  int first_frame = 0;
  std::vector<geometry::Positions> control;  // final finest control points per frame
  RigidSplit split;                          // their multires analysis and rigid motions
  // Per camera, the scale of the images motion and refinement worked on (1 = stored size).
  std::vector<double> image_scales;
  double shape_seconds = 0, motion_seconds = 0, refinement_seconds = 0, retrack_seconds = 0;

  // The stages' brief reports, one line each.
  std::string BriefReport() const;

  const geometry::LoopHierarchy& hierarchy() const { return *shape.hierarchy; }
  // The output surface of frame i (0-based within the processed frames): the limit
  // positions of the finest level's vertices.
  geometry::Positions Surface(int i) const;
};

ReconstructionResult Reconstruct(const vision::Dataset& dataset, const ReconstructionOptions& options,
                                 Progress* progress = nullptr);

}  // namespace subflow::solver
