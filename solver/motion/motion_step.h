// One frame step of motion initialization (method §4.2): the displacement of the finest
// control points from the images of one frame (`before`) to those of another (`after`,
// normally the next or the previous frame), from normal-flow constraints on limit-surface
// samples.
//
//   1. Samples: built once from the reference shape (SampleLimitSurface on the finest
//      level): the same material points (face, u, v) for every frame, so L is constant.
//   2. Visibility of the samples at the current shape (z-buffer, normal, image margin).
//   3. Optionally (highpass_sigma > 0) brightness constancy is written on the images' fine
//      structure, LogHighPass (image_derivatives.h): the log intensities minus their blur,
//      invariant to a gain (exposure, flicker) and to slowly varying shading; the first of
//      several passes on a coarser one (first_highpass_sigma), for its wider linear range.
//   4. Passes p = 0 … P−1 with Gaussian σ_p = image_sigmas[p] (coarse to fine in image
//      scale): smooth both images, build the step constraints at the current guess u = L ∂c
//      (re-linearization / warping, normal_flow_constraints.h), solve for the total
//      displacement coarse to fine over the levels (normal_flow_solver.h). Blob-like
//      motion of ~0.7 px per frame is within the linear range of σ ≈ 1–1.5 px, and the
//      second pass removes most of the linearization error (blob, frames 0 → 1, samples
//      seen twice: end-point error 14.5 % of the motion with one pass at σ = 1, 3.0 % with
//      σ = 1.5 then 1, 2.7 % with a third pass at σ = 1 for 1.7× the time).
// Images are gray per camera (GrayFloat accepts 8/16-bit, float, BGR); they must be
// undistorted (vision::Camera::UndistortImage) when the cameras have distortion.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "solver/motion/normal_flow_solver.h"
#include "solver/observation/sample_visibility.h"
#include "solver/observation/surface_sampling.h"
#include "vision/camera.h"

namespace subflow::solver {

// The largest high-pass σ (pixels) a motion pass accepts: the motion stage's
// highpass_sigma and the retrack's ReconstructionOptions::retrack_highpass, in options files
// and on the command line. Beyond it the high-pass keeps little but the shading it removes.
inline constexpr double kMaxHighPassSigma = 20.0;

struct MotionStepOptions {
  SurfaceSamplingOptions sampling;
  VisibilityOptions visibility;
  NormalFlowSolverOptions solver;
  // Gaussian σ in pixels, one per pass (re-linearization); at least one.
  std::vector<double> image_sigmas = {1.5, 1.0};
  // σ (pixels) of LogHighPass applied to both images before the passes; 0 = the
  // intensities themselves. The first of several passes uses max(highpass_sigma,
  // first_highpass_sigma): on the fine structure alone a 5 px translation from zero is lost
  // (95.7 % sample error; 12.8 % with the coarse first pass, 3.8 % on the intensities),
  // and a first pass on the intensities gives up the invariance to an exposure change.
  // 0 here: motion initialization from the hulls starts from zero motion, and real takes
  // move limbs by several pixels a frame. The retrack, which mostly starts at the refined
  // trajectories, uses 0.7 px by default (ReconstructionOptions::retrack_highpass;
  // docs/shape.md, "Motion on the images' fine structure").
  double highpass_sigma = 0.0;
  double first_highpass_sigma = 8.0;

  void Check() const;  // throws subflow::Error naming the field
};

struct MotionStepReport {
  int samples = 0;            // surface samples
  int visible_samples = 0;    // seen by ≥ 1 camera
  int multi_view_samples = 0; // seen by ≥ 2 cameras
  int constraints = 0;        // of the last pass
  int pruned = 0;             // of the last pass (weight 0)
  int collinearity_pruned = 0;
  // RMS over the last pass's constraints of I_after(p(X + u)) − I_before(p(X)) at the
  // finest σ: for u = 0 (no motion) and for the estimated u.
  double photometric_rms_zero = 0.0;
  double photometric_rms = 0.0;
  double mean_displacement = 0.0;  // mean |∂c| over the finest control points
  // With guesses: the RMS as above at the first pass's σ for the best guess and for zero
  // motion; the guess is used only when it is the better start.
  double guess_rms = 0.0;
  double guess_rms_zero = 0.0;
  bool guess_used = false;
  int guess_index = -1;  // the guess the first pass started at (−1: zero motion)
  int cg_iterations = 0;           // over all passes
  double seconds = 0.0;
};

struct MotionStep {
  geometry::Positions displacement;  // #V(n)×3: c(after) − c(before), finest control points
  NormalFlowSolution solution;       // of the last pass
  MotionStepReport report;
};

class MotionStepEstimator {
 public:
  // Samples the reference shape (finest control points #V(n)×3) as seen by `cameras`,
  // prepares visibility and the solver. Throws subflow::Error on invalid options/sizes.
  MotionStepEstimator(const geometry::LoopHierarchy& hierarchy,
                      const std::vector<vision::Camera>& cameras,
                      const geometry::Positions& reference_control,
                      const MotionStepOptions& options = {});
  // Not copied (nor moved): the solver refers to the samples' limit matrix.
  MotionStepEstimator(const MotionStepEstimator&) = delete;
  MotionStepEstimator& operator=(const MotionStepEstimator&) = delete;

  // Displacement of `control` (finest control points at the `before` frame) between the
  // two sets of images (one per camera). `guesses` (each #V(n)×3; none = start at zero):
  // displacements the first pass may linearize at instead of zero (e.g. the step of
  // trajectories known to be close, or the previous step's: a constant velocity), so that a
  // motion beyond the linear range is still found. The first pass starts at whichever of
  // zero motion and the guesses matches the images best (report.guess_used, guess_index).
  MotionStep Estimate(const geometry::Positions& control, const std::vector<cv::Mat>& before,
                      const std::vector<cv::Mat>& after, const std::vector<geometry::Positions>& guesses = {}) const;

  const SurfaceSamples& samples() const { return samples_; }
  const VisibilityTester& visibility() const { return visibility_; }
  const NormalFlowSolver& solver() const { return solver_; }
  const std::vector<vision::Camera>& cameras() const { return cameras_; }
  const MotionStepOptions& options() const { return options_; }

 private:
  const geometry::LoopHierarchy* hierarchy_;
  std::vector<vision::Camera> cameras_;
  MotionStepOptions options_;
  SurfaceSamples samples_;
  VisibilityTester visibility_;
  NormalFlowSolver solver_;
};

}  // namespace subflow::solver
