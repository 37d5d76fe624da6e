// The product's main job (method §4) as a chain of stages on one LoopHierarchy for the
// whole sequence:
//   shape    shape initialization (solver/shape/shape_init.h)
//   motion   motion initialization by normal flow (solver/motion/motion_init.h)
//   refine   spatio-temporal stereo refinement (solver/stereo/stereo_refinement.h)
//   retrack  the motion pass again on the refined shapes
//   split    rigid / non-rigid split of the final trajectories (solver/rigid/rigid_split.h)
// Each stage is a function of the previous stage's StageState and its options struct.
// `subflow reconstruct` runs them one after another in one process; `subflow shape`,
// `motion`, `refine`, `retrack` and `split` run one each on the StageState the previous
// one wrote to its stage folder (output/stage_folder.h, docs/stages.md): the same
// functions, so both give the same result. The output surface is the limit surface of the
// finest control points at the finest level's vertices (the same vertices and faces at
// every frame, so each vertex is a trajectory).
#pragma once

#include <memory>
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
#include "vision/image_sequence.h"

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
  // σ (pixels) of the retrack's LogHighPass (MotionStepOptions::highpass_sigma of the second
  // motion pass, whose first image pass is at motion.step.first_highpass_sigma; 0 = the
  // intensities). The retrack mostly starts at the refined trajectories, within the fine
  // structure's narrow linear range (where they match the images worse than no motion, as on
  // real takes, from zero). The flow's end-point error falls on every rendered scene (first 8
  // frames, the blob 24: bust_front 0.057 → 0.040, critter_ring 0.110 → 0.089, pair_dome 0.172
  // → 0.145, blob 0.0348 → 0.0321), also on the real-like take_small whose retrack starts
  // every step from zero (1.58 → 1.14; docs/shape.md, "Motion on the images' fine structure").
  double retrack_highpass = 0.7;
  // Register a retrack frame to its refined surface when more than kLostTargetFraction of
  // the tracked surface is out of the snap's reach of it (a limb left behind on a take with
  // large motion), the displacement spread back over the frames since the last registered
  // one. Pose2Sim's single-person demo: the kicked leg left in the air at frames 0 and 99 is
  // gone (17 of 99 frames registered); take_fast (the pose2sim-like synthetic take at 3x
  // motion): observed accuracy P90 18.55 → 16.54 mm, completeness 0.228 → 0.237, EPE_rel
  // 0.555 → 0.577; take_small: 14.28 → 14.66 mm, EPE_rel 1.14 → 2.12 (its last frame's
  // refined surface is worse than the tracked one); the blob and the other scenes register
  // nothing and are unchanged (docs/shape.md, "The retrack registers the frames that lost
  // their refined surface").
  bool retrack_register = true;

  void Check() const;  // throws subflow::Error naming the field
  // The options of the second motion pass: `motion` with hull_weight = retrack_weight,
  // step.highpass_sigma = retrack_highpass, each step started at the refined
  // trajectories' step (guess_from_targets), and lost frames registered (retrack_register).
  MotionInitOptions RetrackOptions() const;
};

// The stages that hand a StageState on, in the order Reconstruct runs them.
enum class Stage { kShape, kMotion, kRefine, kRetrack };
// "shape", "motion", "refine", "retrack": the subcommands and stage folder names.
const char* StageName(Stage stage);
// The stages `options` runs: shape, motion, then refine (unless refine is off) and retrack
// (when refining and retrack is on).
std::vector<Stage> StagesOf(const ReconstructionOptions& options);

// What one stage hands to the next, and all that its stage folder holds.
struct StageState {
  std::shared_ptr<const geometry::LoopHierarchy> hierarchy;
  geometry::TriangleMesh base_mesh;  // T0: the hierarchy's base faces (positions: the reference hull's)
  int first_frame = 0;               // dataset frame of index 0
  int reference_frame = 0;           // dataset frame the motion passes propagate from
  // The silhouettes' source shape initialization used (kAuto resolved per camera by
  // vision::DatasetImages, as shape initialization did).
  vision::EvidenceSource evidence = vision::EvidenceSource::kAuto;
  std::vector<geometry::TriangleMesh> hulls;  // per frame: the visual hull (silhouettes of cameras without masks)
  std::vector<geometry::Positions> control;   // per frame: the finest control points #V(n)×3
  // Per camera, the scale of the images the motion and refinement stages read (1 = the
  // stored size; empty = every camera at 1): chosen once by the shape stage from the
  // reference frame's fitted surface (ShapeInitOptions::image_edge_pixels).
  std::vector<double> image_scales;
  // Per camera, the object's outline the shape stage measured for every frame, which the
  // motion and refinement stages take as that camera's mask (CV_8UC1, 0 / 255, raw image
  // coordinates, any scale of the camera's images); empty = none (masks from the dataset,
  // else the projected hulls). A still set against a plain backdrop has them
  // (ShapeInitResult::outlines).
  std::vector<cv::Mat> outlines;
  // When set, cameras whose silhouettes come from a background image take them, recomputed
  // per frame with these options, as masks (SilhouetteOptions::background_outlines).
  std::optional<vision::SilhouetteOptions> background_outlines;
  // A motion or retrack input seeded from an earlier chunk's stage folder (output::
  // SeedStageInput): that chunk's velocity at the reference frame, where it has one.
  std::optional<MotionLeadIn> lead_in;

  int frame_count() const { return static_cast<int>(control.size()); }
  int reference_index() const { return reference_frame - first_frame; }
  const geometry::LoopHierarchy& Hierarchy() const { return *hierarchy; }
  // Throws subflow::Error naming `source` when the sizes disagree (hulls and control per
  // frame, control rows against the hierarchy's finest level, the reference frame outside).
  void Check(const std::string& source) const;
  // The output surface of index i: the limit positions of the finest level's vertices.
  geometry::Positions Surface(int i) const;
};

// Images of the state's frames as the motion and refinement stages read them (gray images
// and silhouettes: masks where the evidence is masks, else the state's outlines, else the
// projected hulls). `dataset`
// and `state` must outlive the sequence.
vision::ImageSequence StageImages(const vision::Dataset& dataset, const StageState& state);

// The stages. Each returns the state the next one reads and keeps its figures in
// *figures (for report.json).
// The shape stage: with `store` (InitializeShape), the hulls and control points go there
// and the returned state holds none (hulls and control empty; the `shape` command writes
// its stage folder so); without, they are moved from *figures into the state.
StageState RunShapeStage(const vision::Dataset& dataset, const ShapeInitOptions& options, Progress* progress,
                         ShapeInitResult* figures, ShapeFrameStore* store = nullptr);
// Motion initialization from the reference frame's control points, each frame corrected
// towards its own (the shape stage's fit, or, for the retrack pass, the refined shapes).
StageState RunMotionStage(const vision::Dataset& dataset, const StageState& in, const MotionInitOptions& options,
                          Progress* progress, MotionInitResult* figures);
StageState RunRefineStage(const vision::Dataset& dataset, const StageState& in,
                          const StereoRefinementOptions& options, Progress* progress, RefinementResult* figures);
// The rigid / non-rigid split of the state's trajectories.
RigidSplit RunSplitStage(const StageState& in);

}  // namespace subflow::solver
