// Spatio-temporal stereo refinement (method §4.3, eq. 25) with Ceres: the control and
// detail trajectories of one LoopHierarchy are refined jointly over windows of frames so
// that the images the surface patches trace agree across cameras and over time.
//
// Coarse to fine over the levels ℓ = coarsest_level … finest_level (section 3.4). At level
// ℓ the unknowns are, per frame t of the window and per vertex v of level ℓ,
//   ℓ = 0: increments of the base control points c⁰_v(t)           (world xyz, dof 3)
//   ℓ > 0: increments of the details d(ℓ)_v(t) in the Hoppe frame   (n, r, q: dof 3, or
//          F = (n, r, q) of C c(ℓ−1) at v                            the normal only: dof 1)
// and the finest control points follow by synthesis c(i) = C c(i−1) + F(i) d(i), so the
// finer details ride along in their local frames. Surface samples (about one per pixel,
// at least min_density² per patch) are limit points of the current surface, and move
// with the unknowns through the level-ℓ limit stencils (ncc_cost.h).
//
// Residuals per window (frames [w0, w1]; neighbouring frames enter as constants):
//   * stereo: for every patch (face of level ℓ), frame t and pair (i, j) of the
//     max_cameras cameras that see the patch best: √W(i,j) (x̂_i − x̂_j), W = (cos θ_i cos θ_j)^p
//     (θ between the normal and the direction to the camera, p = angle_weight_power), on
//     the samples visible in both (z-buffer visibility of the current surface);
//   * temporal self-correlation: for each of those cameras, the patch at t against the
//     same patch at t + 1 (eq. 25's second sum, Δt = 1): this is what refines the motion
//     along the surface;
//   * silhouette: every patch's middle sample projects inside every silhouette (one-sided
//     signed distance to the outline; masks from the dataset, else the projected visual
//     hulls), and on a mask's outline the surface's rim lies on it (two-sided, rim_band);
//   * regularization, in units of the level's mean edge length h: membrane on the
//     increments (B_v e_v − mean of the neighbours), temporal second differences (of the
//     details' trajectories in their local frames, which a rigid motion leaves unchanged,
//     so only non-rigid acceleration is penalized; of the increments at level 0, whose
//     world trajectories accelerate with the rigid motion), and a small damping;
//   * bounds: |e| ≤ max_step · h per component, and, for the normal-only parametrization,
//     the working volume (the paper's inequality constraints).
// NCC blocks use a Cauchy loss (occlusions the z-buffer misses, specularities).
//
// Visibility and samples are recomputed `rounds` times per level as the shape changes;
// visibility for every window whose frame changed since the last decision
// (refinement_window.h: FrameImageCache).
// Adaptivity: at level ℓ + 1 only the patches whose parent's corners moved by more than
// adaptive_threshold · h_ℓ at level ℓ (in some frame) are refined, and, below the median
// resolved level, only those that still cover min_patch_area (patch_levels.h); the rest
// keep their details. The report says how much of the surface reached each level.
//
// The code, in the order of a level's refinement (all in solver/stereo/):
//   level_sampling.h           the samples of a level and their limit stencils
//   refinement_window.h        a window's frames: bases, samples' positions, visibility
//   photometric_residuals.h    stereo, temporal self-correlation, silhouette
//   regularization_residuals.h membrane, temporal smoothness, damping, bounds
//   window_solve.h             one window's Ceres problem and solve → its increments
//   stereo_refinement.cpp      levels, windows, adaptivity, applying the increments
#pragma once

#include <string>
#include <vector>

#include <ceres/solver.h>

#include "core/progress.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "solver/observation/sample_visibility.h"
#include "vision/image_sequence.h"
#include "vision/working_volume.h"

namespace subflow::solver {

// Whether a level's windows run as two halves side by side (StereoRefinementOptions).
enum class ConcurrentHalves { kOff, kAuto, kOn };
std::string ToString(ConcurrentHalves mode);  // "off", "auto", "on"
// The mode named `text` ("off", "auto", "on"); throws subflow::Error naming `field`.
ConcurrentHalves ParseConcurrentHalves(const std::string& text, const std::string& field);

// The Ceres settings of each window's solve.
struct WindowSolverOptions {
  // Chosen by measurement on the blob (bench/refinement_bench.cpp): sparse_normal_cholesky
  // 9.7 s, sparse_schur 10.9 s, cgnr 11.2 s, iterative_schur 11.9 s for the same result.
  // On the command line by Ceres's names (ceres::StringToLinearSolverType, any case).
  ceres::LinearSolverType linear_solver = ceres::SPARSE_NORMAL_CHOLESKY;
  int max_iterations = 8;            // Ceres iterations per window and round
  int threads = 0;                   // 0 = all hardware threads
  // A relative cost decrease below this ends the solve. The cost of a window falls by
  // 15–80 % in the first iteration and by < 1 % after the second or third (bench: -v logs
  // the cost per iteration); the iterations after that cost as much as the first ones.
  // Measured (refine → retrack → eval, observed accuracy P90 / observed EPE_rel, refine
  // CPU seconds): blob 24 frames, 1e-4 → 0.471 mm / 0.0424 / 124 s, 3e-3 → 0.437 mm /
  // 0.0425 / 89 s, 1e-2 → 0.428 mm / 0.0430 / 74 s; bust_front 8 frames, 1e-4 → 1.109 mm
  // / 0.0568 / 39 s, 3e-3 → 1.095 mm / 0.0556 / 29 s.
  double function_tolerance = 3e-3;
  // Windows with at least this many free vertex blocks (vertex × frame: the unknowns of a
  // normal-only window; a dof-3 vertex counts once) use iterative_solver instead of
  // linear_solver (0 = never). Counted in blocks, not scalar unknowns: with dof 3 on the
  // base level (--slide-at-outlines) pair_dome's windows of ~2,650 blocks (7,950 unknowns)
  // took 65.0 s at that level with cgnr and 47.0 s factorized (the same accuracy: 0.767 /
  // 0.7665 mm P90). The sparse Cholesky factor of a window fills in with its size (a surface
  // over several frames): on the real pose2sim take (HD, 3,000–76,000 unknowns a window)
  // frames 0–11 took 57.7 s in Ceres with sparse_normal_cholesky and 19.3 s with cgnr
  // (mean NCC after 0.6045 / 0.5995), while on the blob (≤ 4,600 unknowns a window)
  // cgnr was no faster (37.4 against 37.8 s) and a little less accurate (0.430 against
  // 0.423 mm P90).
  int iterative_from_unknowns = 8000;
  ceres::LinearSolverType iterative_solver = ceres::CGNR;
  // Its forcing term (Ceres's eta): each step's linear solve stops at this relative
  // residual. Ceres's default, 0.1, gave pose2sim frames 0–11 a mean NCC of 0.5913
  // (sparse_normal_cholesky 0.6045) in 19.4 s of Ceres; 0.01 gave 0.6039 in 26.4 s.
  double iterative_eta = 1e-2;
  // Correlation blocks in their reduced form (PatchCorrelationCost::UseReducedForm): the
  // same steps up to rounding, with an (n + 1) × n Jacobian per block instead of m × n.
  bool reduced_correlation_blocks = true;

  void Check() const;  // throws subflow::Error naming the field (and what Ceres objects to)
  // ceres::Solver::Options with these settings for a window of `vertex_blocks` free
  // increment blocks, silent.
  ceres::Solver::Options ToCeres(int vertex_blocks = 0) const;
  bool Iterative(int vertex_blocks) const;  // whether such a window uses iterative_solver
};

struct StereoRefinementOptions {
  int coarsest_level = 0;
  // −1: automatic, the finest level whose patches still cover min_patch_area pixels² (median
  // over the base faces of their largest projected area, divided by 4 per level, at the
  // middle frame): a correlation window of about 4.5 × 4.5 px needs that much texture. On
  // the blob (320×240) that is level 1 of 3; refining level 2 as well (~12 px² per patch)
  // took twice as long for the same accuracy (0.50 against 0.46 mm P90 on frames 10–12)
  // and end-point error.
  int finest_level = -1;
  double min_patch_area = 20.0;
  // With the automatic finest level: below the median level above, patches are refined
  // where their parent moved and they still cover min_patch_area themselves, down to the
  // deepest level any patch reaches (solver/stereo/patch_levels.h); false = stop at the
  // median level everywhere.
  bool per_patch_levels = true;
  // With per_patch_levels: below min_patch_area, a patch is still refined where one of its
  // parent's corners moved by more than detail_threshold × the parent level's edge length h
  // (large details: a hollow, a thin part or a crease the coarser level could not follow),
  // down to patches of min_detail_patch_area pixels² (patch_levels.h). 0 = off. Measured on
  // the synthetic scenes and the blob (docs/shape.md): 0.2 improved every scene and the
  // blob; 0.1 refined twice as many patches for the same figures on the scenes and made the
  // blob's accuracy worse (0.4357 → 0.4513 mm; 0.2: 0.4267).
  double detail_threshold = 0.2;
  double min_detail_patch_area = 5.0;
  // Levels ≥ this refine the normal detail only (dof 1). Tangential increments are nearly
  // unconstrained by stereo (the correlation does not change when the surface slides along
  // itself), so by default every level keeps the tangential motion of motion
  // initialization and corrects the shape along the normals.
  int normal_only_from_level = 0;
  // On the levels below normal_only_from_level (dof 3), only the vertices at measured
  // outlines (the corners of a patch with an outline or rim block from a camera whose
  // silhouette is the object's own: masks, a plain backdrop, a background image) may slide
  // along the surface; every other vertex stays on its normal (a Ceres SubsetManifold), as
  // with dof 1. Sliding is what the outlines ask for (a web between two legs moved up into
  // the crotch); elsewhere stereo barely constrains it. On rigs all around the subject
  // nearly every base patch has such a block (nothing is held); on a front rig the back is
  // held. Measured on the scenes (docs/shape.md, "Sliding at the outlines"): off by default
  // (normal_only_from_level 0), `--slide-at-outlines` turns it on at the base level.
  bool tangential_only_at_outlines = false;
  // Where a vertex may slide (dof 3), a first difference of its tangential increments over
  // consecutive frames, in frame t's tangent plane: the vertices slide alike over the
  // frames. Sliding a base control point along a curved coarse surface changes the shape,
  // and differently in each frame without it; the retrack then carries that inconsistency
  // into the flow (bust_front EPE_rel +15 %). Measured with --slide-at-outlines in
  // docs/shape.md, "Sliding at the outlines". Option files from before it read 0 (none).
  double slide_coherence = 1.0;
  int window = 6;                  // frames solved jointly
  // Frames shared by consecutive windows: the last `window_overlap` frames of a window are
  // solved again, from their refined state, as the first frames of the next one, so that
  // no frame is only ever refined at a window's edge (where the temporal terms see one
  // side only). At most window − 1 is used (so --window 1 has none); windows advance by
  // window − overlap frames.
  // Measured on blob frames 0–11 (end-point error / accuracy P90, mm; refinement frame
  // solves), with the level-0 term on the world trajectories: 0 → 0.0593 / 0.538 (12),
  // 1 → 0.0536 / 0.553 (14), 2 → 0.0527 / 0.540 (16); with the increments' level-0 term
  // as now, 0 → 0.0637 / 0.509, 2 → 0.0580 / 0.510.
  int window_overlap = 2;
  // Takes of at least 3 windows' frames refined as two halves side by side, each window
  // by window, then a window across the seam with both halves as its context. Ceres 2.1's
  // iterative solver multiplies by the Jacobian on one thread, so while one half's window
  // is in its linear solve the other core is free for the other half's; the sparse
  // Cholesky of the small windows already uses both cores (OpenBLAS). kAuto: side by side
  // at the levels whose windows are solved iteratively (solver.Iterative of the level's
  // unknowns per window). pose2sim, whole take: refinement 416 → 337 s, mean NCC after
  // 0.6173 → 0.6203; the blob's windows are all direct: unchanged (docs/speed.md).
  ConcurrentHalves concurrent_halves = ConcurrentHalves::kAuto;
  // Visibility/sample updates per level (visibility is recomputed at every level anyway).
  int rounds = 1;
  WindowSolverOptions solver;

  double samples_per_pixel = 1.0;
  int min_density = 3;   // at least min_density² samples per patch
  int max_density = 8;
  // Per patch: stereo pairs among the best-facing cameras (3 → 3 pairs; 4 → 6 pairs gave
  // the same figures on the blob at twice the cost).
  int max_cameras = 3;
  int min_samples = 6;   // samples visible in both views of a pair
  double image_sigma = 1.0;        // Gaussian smoothing of the images (pixels)
  double ncc_epsilon = 0.01;       // intensity noise floor of the normalization
  double ncc_loss_scale = 0.5;     // Cauchy scale on ‖r‖² = 2 − 2 NCC; 0 = plain squares
  double temporal_weight = 1.0;    // self-correlation blocks, relative to stereo
  double silhouette_weight = 0.05; // per pixel of outline distance
  // Coarsest level with outline blocks. One block acts at a patch's middle sample and moves
  // all of the patch's support, which on the base level is a large part of the subject.
  // Starting at level 1 was measured on every scene (docs/shape.md, "The outline term on the
  // base level"): with exact masks it helps (observed accuracy P90 blob 0.422 → 0.291 mm,
  // bust_front 0.746 → 0.610 px, critter_ring 1.260 → 1.021 px) or costs (pair_dome 0.948 →
  // 0.984, mug_ring 4.131 → 4.579); without masks it costs critter_nomasks 1.167 → 1.819 px.
  // Not one way better: the base level keeps its outline blocks.
  int silhouette_from_level = 0;
  // The rim: where a patch straddles a camera's contour generator (its samples face the
  // camera and face away) and its sample nearest the contour generator projects within
  // rim_band pixels inside that camera's outline (or outside it), with nothing of the
  // surface just beyond it in the image, that sample is drawn onto the outline from both
  // sides, with silhouette_weight — only for outlines that are the object's own (masks),
  // not for projected hulls, which only bound it. Without it nothing pulls a surface out towards
  // the outline: correlation stops outline_margin pixels inside it and the outline term is
  // one-sided, so grazing regions sank inwards (docs/shape.md, "The rim"). 0 = off.
  double rim_band = 2.0;
  // Pair weight W(i, j) = (cos θ_i cos θ_j)^p: grazing views see the texture foreshortened
  // and blurred along the surface, which biases the correlation optimum.
  double angle_weight_power = 3.0;
  // Samples closer than this to a silhouette's outline (pixels) are not correlated in that
  // camera: their smoothed intensities mix in the background.
  double outline_margin = 3.0;
  double membrane_weight = 0.3;
  double temporal_smoothness = 0.3;
  double damping = 0.01;
  double max_step = 1.0;           // bound on each increment, in edge lengths h
  double adaptive_threshold = 0.02;  // in edge lengths h of the level
  VisibilityOptions visibility;

  void Check() const;  // throws subflow::Error naming the field
};

struct RefinementLevelReport {
  int level = 0;
  int dof = 0;
  int patches = 0;             // faces of the level
  int active_patches = 0;      // refined at this level (adaptivity)
  double active_fraction = 0;  // active / all
  int parameters = 0;          // scalar unknowns over all windows and rounds (last round)
  int residual_blocks = 0;     // over all windows (last round)
  int windows = 0;             // temporal windows solved per round
  double mean_increment = 0;   // mean |B e| over vertices and frames (world units)
  double seconds = 0;
  double solver_seconds = 0;   // inside ceres::Solve
  int iterations = 0;          // Ceres iterations over all windows and rounds
  int iterative_windows = 0;   // windows solved by solver.iterative_solver (last round)
  bool concurrent_halves = false;  // the windows ran as two halves side by side
};

struct RefinementFrameReport {
  int frame = 0;
  // Mean NCC over the stereo pairs of all patches (ε-regularized), before and after.
  double ncc_before = 0, ncc_after = 0;
  int stereo_pairs = 0;
  // RMS silhouette distance (pixels) of the outline and rim blocks, before and after.
  double silhouette_rms_before = 0, silhouette_rms_after = 0;
};

struct RefinementResult {
  std::vector<geometry::Positions> control;  // finest control points per frame
  std::vector<RefinementLevelReport> levels;
  std::vector<RefinementFrameReport> frames;
  double seconds = 0;

  // One line: levels with their active fractions, iterations, mean NCC before → after, seconds.
  std::string BriefReport() const;
};

// `control`: the finest control points of every frame of `images` (#V(n)×3 each,
// motion-initialized trajectories); the images' gray frames and silhouettes (the
// silhouette term is left out where a camera has none). Throws subflow::Error on invalid
// options or sizes.
RefinementResult RefineStereo(const vision::ImageSequence& images, const geometry::LoopHierarchy& hierarchy,
                              const std::vector<geometry::Positions>& control,
                              const vision::Bounds& bounds, const StereoRefinementOptions& options,
                              Progress* progress = nullptr);

}  // namespace subflow::solver
