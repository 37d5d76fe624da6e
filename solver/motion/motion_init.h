// Motion initialization over a sequence (method §4.2): trajectories of the control points
// of ONE LoopHierarchy for every frame, from normal flow.
//
//   reference frame r: c(r) = the given fitted finest control points
//   forward  f = r … F−2:  c(f+1) = c(f) + ∂c(f → f+1)   (MotionStepEstimator on the images
//                                                         of frames f and f + 1)
//   backward f = r … 1:    c(f−1) = c(f) + ∂c(f → f−1)
//   after each step, when that frame has its own fitted control points (shape
//   initialization on its visual hull), the normal component is corrected towards their
//   limit surface (SnapToSurface, blend `hull_weight`, |distance| ≤ hull_max_distance):
//   the hull bounds the drift along the normals; the tangential correspondence comes from
//   the image motion alone. Optionally (registration.enabled), before that snap, a surface
//   that drifted from the frame's fit by more than the registration's gate (a quarter base edge, on average over the fit
//   within reach) is registered to it (solver/shape/surface_registration.h, on the base
//   control points of the step's multi-resolution analysis; the details ride along in
//   their local frames): over a long chain the image motion of a fast, thin part (a
//   kicking leg, 44 frames from pose2sim's reference) slides it off its place, sideways,
//   where a snap along the normals cannot bring it back.
// Every frame keeps the hierarchy's connectivity: no re-meshing over time.
//
// The rigid / non-rigid split of the trajectories is a stage of its own
// (solver/rigid/rigid_split.h: SplitRigidMotion).
#pragma once

#include <string>
#include <vector>

#include "core/progress.h"
#include "geometry/closest_point.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "solver/motion/motion_step.h"
#include "solver/shape/surface_registration.h"
#include "vision/image_sequence.h"

namespace subflow::solver {

// More than a quarter of the surface out of the correction's reach of its target
// (MotionFrameReport::correction_unreached): the chain has lost the target there, e.g. a limb
// left behind far from the reference frame. The retrack registers such frames
// (ReconstructionOptions::retrack_register) and warns when they stay lost.
constexpr double kLostTargetFraction = 0.25;

struct MotionInitOptions {
  MotionStepOptions step;
  // Normal correction towards each frame's own fitted surface, when given: blend weight in
  // [0, 1] (0 = off), largest correction (world units; 0 = 3 × the mean finest edge
  // length of the reference shape), snapping iterations.
  double hull_weight = 0.5;
  double hull_max_distance = 0.0;
  int hull_iterations = 2;
  // Registration to each frame's fitted surface before the snap (see above); its gate
  // leaves a surface that follows its fit alone. Off by default: on pose2sim_multiperson it
  // registered 54 of 99 steps for +54 s (+20 %) of the motion stage, covered one more shin
  // at frame 6 in one camera and changed nothing visible at frame 90, while the snap's RMS
  // distance to the fits rose (median 11.8 → 13.9 mm); the synthetic scenes and the blob
  // never trip its gate (docs/shape.md, 2026-12-05).
  SurfaceRegistrationOptions registration = [] {
    SurfaceRegistrationOptions off;
    off.enabled = false;
    return off;
  }();
  // Start each step's first pass at the displacement from the current control points to
  // the target frame's own surface (when it has one) instead of at zero: for the retrack
  // pass, whose targets are the refined shapes — one connectivity whose vertices already
  // follow the material — not for independent per-frame fits (shape initialization's).
  bool guess_from_targets = false;
  // Also offer the first pass the chain's previous step (a constant velocity: at video rates
  // a point's motion changes little from one frame to the next), taken only where it
  // matches the images better than zero motion and the other guesses. Measured on the
  // scenes (docs/shape.md, "A constant velocity as the first pass's start").
  bool guess_previous_step = true;
  // When a frame is registered, spread the registration's displacement back over the
  // chain's frames since the previous registered frame (or the reference), in proportion
  // to their distance from it: the surface that fell behind its targets over those frames
  // catches up steadily instead of jumping at one frame.
  bool spread_registration = false;
  // Register a frame only when more than this fraction of its surface is out of the snap's
  // reach of its target (correction_unreached before the registration: the chain lost part
  // of the target, e.g. a swung limb), besides the registration's own distance gate;
  // 0 = the distance gate alone.
  double registration_min_unreached = 0.0;
  // Run the chains after and before the reference frame side by side (the same result as
  // one after the other).
  bool concurrent_chains = true;

  void Check() const;  // throws subflow::Error naming the field
};

// Where a step's first pass started.
enum class GuessSource { kZero, kTarget, kPreviousStep };
const char* ToString(GuessSource source);

struct MotionFrameReport {
  int frame = 0;
  std::vector<GuessSource> guesses_offered;  // the starts the first pass was offered besides zero
  int from_frame = -1;  // the frame it was propagated from; −1 for the reference frame
  bool identical_images = false;  // every camera's image equals from_frame's (a duplicated frame)
  MotionStepReport step;
  bool corrected = false;           // normal correction applied
  double correction_rms_before = 0.0;   // RMS normal distance to the frame's fitted surface
  double correction_rms_applied = 0.0;  // RMS length of the correction applied to the control points
  // Fraction of the finest limit points whose normal line meets the frame's fitted surface
  // nowhere within the correction's reach (first pass): surface that the correction cannot
  // bring back, e.g. a limb the chain left behind.
  double correction_unreached = 0.0;
  // The same before the registration, when its gate measured it (registration_min_unreached
  // > 0; else −1).
  double unreached_before_registration = -1.0;
  SurfaceRegistrationReport registration;  // measured whenever corrected; `applied` when registered

  // The start the first pass took: one of guesses_offered (step.guess_index), or zero motion.
  GuessSource guess_source() const;
};

struct MotionInitResult {
  int reference_frame = 0;
  std::vector<geometry::Positions> control;  // per frame: finest control points #V(n)×3
  std::vector<MotionFrameReport> frames;     // per frame
  double seconds = 0.0;

  // One line: frames, reference, photometric RMS of zero motion → estimated, seconds.
  std::string BriefReport() const;
  // The frames where more than `fraction` of the surface was beyond the correction's reach
  // of the frame's fitted surface (correction_unreached), in order.
  std::vector<int> FramesOffTarget(double fraction) const;
};

// One step's correction towards its frame's fitted surface `fit` (see the file comment):
// the registration (`registration` built with options.registration, its gate deciding),
// then the snap along the normals (hull_weight, |correction| ≤ max_correction,
// hull_iterations). Fills report->corrected, correction_rms_before/applied and
// registration; `registration_shift` (optional) receives the registration's displacement
// of the finest control points (empty when not registered). Returns the corrected finest
// control points.
geometry::Positions CorrectTowardsFit(const geometry::LoopHierarchy& hierarchy,
                                      const SurfaceRegistration& registration,
                                      const geometry::Positions& control, const geometry::ClosestPointTree& fit,
                                      const MotionInitOptions& options, double max_correction,
                                      MotionFrameReport* report, geometry::Positions* registration_shift = nullptr);

// A chain that continues another's (a chunk of a plan seeded at its first or last frame,
// docs/cluster.md): the other chain's velocity at the reference frame, from its control
// points there and at the frame beside it, offered to the first step here as its previous
// step (MotionInitOptions::guess_previous_step). Within a chain the previous step is the
// flow alone; this difference of control points also holds the other chain's corrections.
struct MotionLeadIn {
  int direction = 0;          // +1: the chain continues forwards (the frame beside is before); −1: backwards
  geometry::Positions step;   // #V(n)×3: control(reference) − control(reference − direction)
};

// Trajectories for the frames of `images` (its gray images; frames and reference_frame
// are window frames). `initial_control`: either one matrix (the reference frame's fitted
// finest control points) or one per frame (images.frame_count entries; the reference
// frame's must be non-empty, others may be empty = no fit for that frame, no correction
// there). `lead_in` (optional): the chain in its direction starts with that previous step.
// Throws subflow::Error on sizes, a reference frame out of range, or invalid options.
MotionInitResult InitializeMotion(const vision::ImageSequence& images,
                                  const geometry::LoopHierarchy& hierarchy,
                                  const std::vector<geometry::Positions>& initial_control,
                                  int reference_frame, const MotionInitOptions& options,
                                  Progress* progress = nullptr, const MotionLeadIn* lead_in = nullptr);

}  // namespace subflow::solver
