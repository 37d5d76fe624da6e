// Motion initialization over a sequence (method §4.2, §5): trajectories of the control
// points of ONE LoopHierarchy for every frame, from normal flow, and the rigid / non-rigid
// split of the result.
//
//   reference frame r: c(r) = the given fitted finest control points
//   forward  f = r … F−2:  c(f+1) = c(f) + ∂c(f → f+1)   (MotionStepEstimator on the images
//                                                         of frames f and f + 1)
//   backward f = r … 1:    c(f−1) = c(f) + ∂c(f → f−1)
//   after each step, when that frame has its own fitted control points (shape
//   initialization on its visual hull), the normal component is corrected towards their
//   limit surface (SnapToSurface, blend `hull_weight`, |distance| ≤ hull_max_distance):
//   the hull bounds the drift along the normals; the tangential correspondence comes from
//   the image motion alone.
// Every frame keeps the hierarchy's connectivity: no re-meshing over time.
//
// Afterwards the finest control points of every frame are analyzed into MultiresShapes
// (base c⁰ and details in local frames, geometry::AnalyzeTrajectory), and the rigid motion
// of every step is fitted to the base control trajectories (FitRigidMotions: Cayley
// convention, midpoints, see rigid_motion.h). Flows are per frame step: control_flow[f] =
// c(f + 1) − c(f). Per-vertex non-rigid flow and motion energy for any vertex set
// evaluated at every frame (e.g. the output tessellation L_t c(f)) come from AnalyzeFlow.
#pragma once

#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "geometry/loop_hierarchy.h"
#include "geometry/multires_shape.h"
#include "core/progress.h"
#include "geometry/triangle_mesh.h"
#include "solver/motion_step.h"
#include "solver/rigid_motion.h"
#include "vision/camera.h"
#include "vision/dataset.h"

namespace subflow::solver {

struct MotionInitOptions {
  MotionStepOptions step;
  // Normal correction towards each frame's own fitted surface, when given: blend weight in
  // [0, 1] (0 = off), largest correction (world units; 0 = 3 × the mean finest edge
  // length of the reference shape), snapping iterations.
  double hull_weight = 0.5;
  double hull_max_distance = 0.0;
  int hull_iterations = 2;

  void Check() const;  // throws subflow::Error naming the field
};

struct MotionFrameReport {
  int frame = 0;
  int from_frame = -1;  // the frame it was propagated from; −1 for the reference frame
  MotionStepReport step;
  bool corrected = false;           // normal correction applied
  double correction_rms_before = 0.0;  // RMS normal distance to the frame's fitted surface
  double correction_rms_after = 0.0;
};

struct MotionInitResult {
  int reference_frame = 0;
  std::vector<geometry::Positions> control;       // per frame: finest control points #V(n)×3
  geometry::Trajectory trajectory;                // per frame: multires analysis of `control`
  std::vector<geometry::Positions> control_flow;  // per frame: c(f+1) − c(f); zero at the last
  std::vector<RigidMotion> rigid;                 // per step f → f+1 (frame_count − 1)
  std::vector<MotionFrameReport> frames;          // per frame
  double seconds = 0.0;
};

// Images of a camera at a frame: gray (any type GrayFloat accepts), undistorted.
using GrayImageLoader = std::function<cv::Mat(int camera, int frame)>;

// `initial_control`: either one matrix (the reference frame's fitted finest control
// points) or one per frame (frame_count entries; the reference frame's must be non-empty,
// others may be empty = no fit for that frame, no correction there). Throws
// subflow::Error on sizes, a reference frame out of range, or invalid options.
MotionInitResult InitializeMotion(const std::vector<vision::Camera>& cameras, int frame_count,
                                  const GrayImageLoader& gray,
                                  const geometry::LoopHierarchy& hierarchy,
                                  const std::vector<geometry::Positions>& initial_control,
                                  int reference_frame, const MotionInitOptions& options,
                                  Progress* progress = nullptr);

// The same on a dataset: Dataset::Gray, undistorted when a camera has distortion.
MotionInitResult InitializeMotion(const vision::Dataset& dataset,
                                  const geometry::LoopHierarchy& hierarchy,
                                  const std::vector<geometry::Positions>& initial_control,
                                  int reference_frame, const MotionInitOptions& options,
                                  Progress* progress = nullptr);

}  // namespace subflow::solver
