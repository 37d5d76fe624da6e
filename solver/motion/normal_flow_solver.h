// The sparse least-squares solution of the stacked normal-flow constraints (method §4.2,
// eq. 20–24), coarse to fine: base control motion first, then detail motion level by level.
//
// Unknowns. The motion (displacement over the step) of the finest control points is
// parameterized as in the synthesis of eq. 22 with the local frames held fixed over the step
// (the linearization the method uses, D^i = F^i):
//   ∂c_n = Σ_{i=lo..hi} P_i δ_i,   P_i = C(n−1) ⋯ C(i)  (#V(n)×#V(i), P_n = I),
//   δ_lo = ∂c_lo (the base control motion, lo = coarsest_level, normally 0),
//   δ_i  = F(i) ∂d(i) for i > lo (detail motion; world vectors, so ∂d(i) = F(i)ᵀ δ_i in the
//          frames of the current shape — LocalDetailMotion below).
// A sample s = L c_n moves by L ∂c_n (eq. 13), so each constraint of
// normal_flow_constraints.h, g_cᵀ (L ∂c_n)_s = b_c, is linear in every δ_i.
//
// Energy for level i, solved in the order lo, lo+1, …, hi with the coarser levels fixed:
//   E_i(δ_i) = Σ_c w_c (g_cᵀ (L D_i)_s − b_c)²          D_i = Σ_{j<i} P_j δ_j + P_i δ_i
//            + λ_i ‖U_i (W_i + δ_i − ρ_i)‖²              smoothness (the aperture problem)
//            + μ_i ‖δ_i‖²                               damping of unconstrained details
//   U_i the umbrella Laplacian of level i (eq. 16), W_i = Σ_{j<i} C(i−1)⋯C(j) δ_j the
//   motion of level i's control points implied by the coarser levels, so the smoothness
//   term acts on level i's whole motion field, not only on the increment.
//   ρ_i = v + ω × m_i is the rigid part of the motion (§5), fitted (FitRigidMotion, Cayley
//   midpoints) to the previous pass's estimate and evaluated at level i's control points
//   m_i (multires analysis of the midpoint shape); ρ = 0 on the very first pass. The
//   umbrella operator does not annihilate rotations on a curved surface (U(ω × x) =
//   ω × U x ≠ 0), so without ρ the smoothness term biases rotations towards zero (≈ 1 %
//   of the motion at smoothness 0.1 on the test potato); with it only the non-rigid part of
//   the field is smoothed (rigid_invariant_smoothness).
//   Scaling (independent of the mesh resolution and of the world units):
//     κ_i = mean diagonal of the data term's normal matrix on level i (per unknown),
//     λ_i = smoothness · κ_i · (R/h_i)⁴,  R = RMS distance of the control points from their
//     centroid, h_i = mean edge length of level i (h_n measured, h_i = 2^{n−i} h_n);
//     the umbrella operator of a smooth field scales like h²·Δ, so this is
//     smoothness · R⁴ ∫ |Δv|² per unit of data, a fixed continuous energy;
//     μ_i = detail_damping · κ_i for i > lo, 1e−9 κ_lo on the base (definiteness only).
// Data matrices: P_iᵀ Lᵀ M L P_i (M the per-sample 3×3 blocks Σ w g gᵀ) is assembled
// directly on the finest ESTIMATED level hi from the samples' level-hi limit stencils
// L P_hi, and carried to coarser levels by C(i)ᵀ · C(i); the right-hand sides are
// (L P_i)ᵀ (h − M L D). No matrix of the finest level's size (4^{n−hi} × level hi's) is
// assembled when hi < n.
// Each level's normal equations are solved by preconditioned conjugate gradients
// (conjugate_gradient.h: Eigen's iteration with a 3×3 block-Jacobi preconditioner, one
// block per control point, and a parallel matrix–vector product), warm-started from the
// previous pass.
//
// Robustness (pruning bad correspondences, then re-weighting):
//   * Collinearity (constraint_collinearity.h): per sample seen by ≥ collinearity_min_cameras
//     cameras, the constraint planes must meet in one line; single inconsistent
//     measurements are removed, samples that stay inconsistent are pruned as a whole.
//   * IRLS. After each solve, the residuals r_c = g_cᵀ (L D)_s − b_c of the whole field get
//     Tukey weights (threshold robust_threshold · σ, σ = max(1.4826 · MAD, noise_floor));
//     the system is re-solved reweighting_iterations times.
//   Final weight = collinearity weight × IRLS weight.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "geometry/limit_evaluation.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "solver/motion/level_matrices.h"
#include "solver/motion/multigrid_preconditioner.h"
#include "solver/motion/normal_flow_constraints.h"
#include "solver/rigid/rigid_motion.h"

namespace subflow::solver {

struct NormalFlowSolverOptions {
  // α: smoothness weight (dimensionless, see above). 0.003 gave the lowest end-point error
  // on the blob (0.001: +8 %, 0.01: +16 %, 0.1: ×3), the same for hierarchies with 2562
  // and 10242 finest control points (the scaling makes it resolution-independent).
  double smoothness = 0.003;
  bool rigid_invariant_smoothness = true;  // smooth the motion minus its rigid part ρ
  double detail_damping = 1e-2;   // β: ridge on detail motions, relative to the data
  int coarsest_level = 0;         // level solved first (the base control points)
  // Finest level whose details are solved; −1 = automatic: the finest level whose faces
  // carry on average ≥ min_samples_per_face samples (patches of ≥ 4×4 pixels by default:
  // with ~1 sample per pixel and images smoothed over σ ≈ 1–1.5 px, motion detail finer
  // than that is hardly observable; finer levels follow their parents by refinement). On
  // the blob, estimating one more level changed the end-point error by < 3 % and doubled
  // (2562 finest control points) or tripled (10242) the time.
  int finest_level = -1;
  double min_samples_per_face = 16.0;
  int reweighting_iterations = 2; // IRLS re-solves after the first (0 = plain least squares)
  double robust_threshold = 4.685;  // Tukey constant in robust standard deviations
  // Floor of the robust scale σ (intensity, images in [0, 1]): residuals this small are
  // never outliers (≈ half a grey level of 255; keeps exact or noise-free data unpruned).
  double noise_floor = 0.002;
  bool collinearity_pruning = true;
  int collinearity_min_cameras = 3;  // per-sample test needs K ≥ this (≥ 3: 2 planes always meet)
  double cg_tolerance = 1e-4;     // relative residual of each level's normal equations
  // Relative residual of the solves whose only use is the next IRLS weights (every solve
  // but the last of a Solve call): the weights need the residuals to a few per cent, not
  // the solution to 1e-4. Measured on the 4-camera HD take (pose2sim, 3 steps): 1e-4 →
  // 5,542 CG iterations and 3.76 s a step, 1e-3 → 3,666 and 3.04 s, photometric RMS equal
  // to 4 digits; blob (3 levels, 12 frames): end-point error 0.04169 → 0.04168 relative.
  double cg_reweighting_tolerance = 1e-3;
  int cg_max_iterations = 500;
  // Precondition the CG of the levels above the coarsest with at least
  // multigrid_min_vertices control points by a V-cycle over the coarser levels
  // (multigrid_preconditioner.h) instead of block Jacobi alone: the same solution to the
  // same tolerance in far fewer iterations, for a setup (power iterations, the base level's
  // Cholesky factor) that small levels do not repay. Measured (docs/speed.md): pose2sim
  // level 2 (8,196 control points) 250–500 → 4–5 iterations, 4.3× faster; its level 1
  // (2,052) 85–248 → 4–5, as fast; the blob's level 1 (642) 57 → 3 iterations but a step
  // 17 % slower.
  bool multigrid = true;
  int multigrid_min_vertices = 2000;

  void Check() const;  // throws subflow::Error naming the field
};

struct LevelSolveReport {
  int level = 0;
  int unknowns = 0;
  int cg_iterations = 0;
  double cg_error = 0.0;           // relative residual reached
  double smoothness_weight = 0.0;  // λ_i
  double data_stiffness = 0.0;     // κ_i
};

struct NormalFlowSolution {
  geometry::Positions displacement;           // ∂c_n: #V(n)×3, finest control points
  std::vector<geometry::Positions> level_motion;  // δ_i (world), indexed by level; empty
                                                  // for levels that are not estimated
  Eigen::VectorXd weights;               // per constraint, final weight in [0, 1]
  Eigen::VectorXd collinearity_weights;  // per constraint (1 when not tested)
  double robust_scale = 0.0;             // σ of the last IRLS weighting (intensity)
  int pruned = 0;                        // constraints with final weight 0
  int collinearity_pruned = 0;           // of which zeroed by the collinearity test
  double rms_residual_zero = 0.0;        // √(mean b²): residual of zero motion, all rows
  double rms_residual = 0.0;             // √(mean r²) at the solution over unpruned rows
  std::vector<LevelSolveReport> levels;  // of the final pass
  int cg_iterations = 0;                 // total over all passes and levels
  RigidMotion rigid;                     // rigid part of `displacement` (Cayley midpoints)
};

class NormalFlowSolver {
 public:
  // `sample_limit` is L (#S × #V(n), SurfaceSamples::limit of the finest level, compressed);
  // the solver keeps a reference to it and to `hierarchy`, which must outlive it (on an HD
  // take L is hundreds of MB: MotionStepEstimator owns the one copy).
  // `reference_control` (#V(n)×3) fixes the length scales R and h_n. Precomputes the
  // prolongations, Laplacians and the sparsity pattern of Lᵀ L. Throws subflow::Error on
  // invalid options or sizes.
  NormalFlowSolver(const geometry::LoopHierarchy& hierarchy,
                   const geometry::SparseMatrix& sample_limit,
                   const geometry::Positions& reference_control,
                   const NormalFlowSolverOptions& options);
  // Not from a temporary L or hierarchy: the solver would refer to them after they are gone.
  NormalFlowSolver(const geometry::LoopHierarchy& hierarchy, geometry::SparseMatrix&& sample_limit,
                   const geometry::Positions& reference_control, const NormalFlowSolverOptions& options) = delete;
  NormalFlowSolver(geometry::LoopHierarchy&& hierarchy, const geometry::SparseMatrix& sample_limit,
                   const geometry::Positions& reference_control, const NormalFlowSolverOptions& options) = delete;

  // Solves for the displacement of the finest control points `control` (#V(n)×3, the shape
  // the constraints' samples lie on). `warm_start` (optional): a previous solution for the
  // same `control`; it seeds the CG iterations and the rigid part ρ of the first pass.
  NormalFlowSolution Solve(const NormalFlowConstraints& constraints,
                           const geometry::Positions& control,
                           const NormalFlowSolution* warm_start = nullptr) const;

  // L ∂c_n: the samples' motion (#S×3) for a finest control displacement.
  geometry::Positions SampleMotion(const geometry::Positions& displacement) const;

  int coarsest_level() const { return lo_; }
  int finest_estimated_level() const { return hi_; }
  const NormalFlowSolverOptions& options() const { return options_; }

 private:
  using Sparse = Eigen::SparseMatrix<double>;  // column-major, for CG and products

  // rigid_part[i]: ρ_i (#V(i)×3) for the estimated levels, or empty for ρ = 0.
  // `sample_motion` receives L ∂c_n of the solution (#S×3). Each level's CG stops at the
  // relative residual `cg_tolerance`.
  void SolveLevels(const NormalFlowConstraints& constraints, const Eigen::VectorXd& weights,
                   const std::vector<geometry::Positions>& rigid_part, double cg_tolerance,
                   NormalFlowSolution* solution, geometry::Positions* sample_motion) const;
  // The V-cycle preconditioner of level `level`'s CG matrix `A` (data + stiffness ·
  // regularizer): the coarser levels' data sums `data` with the regularizer weights scaled
  // as multigrid_preconditioner.h says.
  std::unique_ptr<MultigridPreconditioner> MakeMultigrid(const BlockSparseMatrix& A,
                                                         const std::vector<std::vector<double>>& data, int level,
                                                         double stiffness) const;
  // ρ_i of the file comment for the displacement `previous` of `control`.
  std::vector<geometry::Positions> RigidPart(const geometry::Positions& control,
                                             const geometry::Positions& previous) const;

  // The samples as limit points of the finest estimated level: L_hi = L P_hi (#S × #V(hi)).
  // The limit surface of C(i) c is that of c, so a row of L_hi is level hi's own limit
  // stencil (the 1-ring of the face holding the sample, ~12 control points), not the union
  // of the finest stencil's ancestors; entries that cancel to rounding noise are dropped.
  // The data matrix is accumulated there once per solve (DataSums) and carried to the
  // coarser levels by C(i)ᵀ · C(i) (level_matrices.h); the finest level's (#V(n) ≫ #V(hi))
  // is never formed.
  struct SampleStencils {
    geometry::SparseMatrix limit;        // L_hi, row-major
    SymmetricPattern pattern;            // of L_hiᵀ L_hi (#V(hi) square)
    // Row e = (a, b), a ≤ b, of the pattern: l_sa l_sb in the column of every sample s
    // whose stencil holds both (row-major, samples ascending; lower entries' rows empty).
    geometry::SparseMatrix entry_weights;
  };
  // Drops the rounding-noise entries of `limit` and builds the pair pattern, in `out`
  // (filled in place: Eigen 3.4's SparseMatrix has no move assignment, and on an HD take
  // a copy of these is hundreds of MB).
  static void MakeStencils(const geometry::SparseMatrix& limit, SampleStencils* out);
  // The block sums (level_matrices.h) of L_hiᵀ M L_hi = P_hiᵀ (Lᵀ M L) P_hi for per-sample
  // symmetric 3×3 blocks M (#S×6: xx xy xz yy yz zz).
  static std::vector<double> DataSums(const SampleStencils& stencils,
                                      const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>& M);

  const geometry::LoopHierarchy* hierarchy_;
  NormalFlowSolverOptions options_;
  int n_ = 0, lo_ = 0, hi_ = 0;
  const geometry::SparseMatrix* limit_ = nullptr;  // L, row-major (the caller's)
  SampleStencils stencils_;            // of level hi
  // L P_i (#S × #V(i)), by level lo..hi−1; level hi's is stencils_.limit. Their transposes
  // are applied without being formed (TransposeParallelProduct).
  std::vector<geometry::SparseMatrix> level_limit_;
  const geometry::SparseMatrix& LevelLimit(int level) const {
    return level == hi_ ? stencils_.limit : level_limit_[level];
  }
  std::vector<geometry::SparseMatrix> coarsening_;  // block sums of level i+1 → i, by level lo..hi−1
  std::vector<LevelMatrix> level_matrix_;  // CG matrix structure, by level lo..hi
  std::vector<Sparse> prolongation3_;  // P_i ⊗ I3 (3#V(n) × 3#V(i)), by level
  std::vector<Sparse> smoothness3_;    // U_iᵀ U_i ⊗ I3, by level
  std::vector<double> length_ratio4_;  // (R/h_i)⁴ by level
};

// The detail motions in the local frames of `finest_control`'s multires analysis:
// ∂d(i) = F(i)ᵀ δ_i for the estimated levels i > coarsest (empty matrices elsewhere).
std::vector<geometry::Positions> LocalDetailMotion(const geometry::LoopHierarchy& hierarchy,
                                                   const geometry::Positions& finest_control,
                                                   const NormalFlowSolution& solution,
                                                   int coarsest_level);

}  // namespace subflow::solver
