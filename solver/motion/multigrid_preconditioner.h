// A V-cycle over the levels of the Loop hierarchy as the preconditioner of the normal-flow
// solver's conjugate gradients (normal_flow_solver.h, conjugate_gradient.h).
//
// Why. The normal equations of level i are data + λ_i U_iᵀU_i + μ_i I: a bi-Laplacian on
// the level's control net, stiff where the data are weak (unseen surface, the aperture
// problem). Block Jacobi leaves the smooth error of such a system nearly untouched, so the
// CG's iteration count grows with the level's size: on the real pose2sim take (HD, 4
// cameras, level 2 of 8,196 control points) 250–500 iterations a solve, often stopping at
// the 500-iteration cap above the tolerance, and 70 % of the motion stage's time. Smooth
// error is what the coarser levels represent: their control points, refined by C, span it.
//
// The cycle, for the matrix A_k of level k and the residual r (symmetric V(ν, ν)):
//   x  = ν sweeps of damped block Jacobi from 0:  x ← x + ω D⁻¹ (r − A_k x)
//   x += C e,  e = the cycle of level k − 1 on Cᵀ (r − A_k x)     (C = C(k−1), refinement)
//   x  = ν more sweeps as above
// down to the coarsest level, solved exactly (sparse Cholesky; block Jacobi if that fails).
// Pre- and post-smoothing are the same symmetric operator, so the cycle is a symmetric
// linear map, positive definite when each smoother converges (ω · λmax(D⁻¹A) < 2): ω =
// 4 / (3 λ̂), λ̂ ≥ λmax estimated by power iteration (the damping that best smooths a
// Laplacian, 2/3 for λmax = 2) — what plain CG needs of a preconditioner.
//
// Coarse operators. The caller gives each coarser level's matrix: the data part carried by
// Cᵀ · C (exactly Galerkin, level_matrices.h) and the regularizer rediscretized on the
// coarse net with the fine weights scaled by 4 per level (a smooth field on a net with 4×
// the vertices and ½ the edge length has 4× the umbrella energy and 4× the damping energy
// of the same field on the coarser net). The preconditioner only has to be close to A⁻¹ for
// the CG to converge fast; the CG still solves A x = b to its tolerance.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "geometry/loop_operators.h"
#include "solver/motion/block_jacobi_preconditioner.h"
#include "solver/motion/conjugate_gradient.h"

namespace subflow::solver {

struct MultigridOptions {
  int sweeps = 2;              // ν: smoothing sweeps before and after the coarse correction
  int power_iterations = 12;   // for λmax(D⁻¹A) of each smoothed level
  double lambda_margin = 1.1;  // λ̂ = margin × the power iteration's estimate
};

class MultigridPreconditioner {
 public:
  // `fine`: the matrix the CG solves (level k, kept by reference: it must outlive this).
  // `coarse[j]`: the matrix of level k − 1 − j (taken over). `refinement[j]`: C from level
  // k − 1 − j to level k − j (#V(k − j) × #V(k − 1 − j), per vertex; kept by reference).
  // Throws subflow::Error when the sizes disagree.
  MultigridPreconditioner(const BlockSparseMatrix& fine, std::vector<BlockSparseMatrix> coarse,
                          std::vector<const geometry::SparseMatrix*> refinement, const MultigridOptions& options = {});
  ~MultigridPreconditioner();
  MultigridPreconditioner(const MultigridPreconditioner&) = delete;
  MultigridPreconditioner& operator=(const MultigridPreconditioner&) = delete;

  // z = M⁻¹ r (one V-cycle from zero).
  Eigen::VectorXd solve(const Eigen::VectorXd& r) const;

  int levels() const { return static_cast<int>(levels_.size()); }
  // ω of level j (0 = the finest) and whether the coarsest level is solved exactly.
  double damping(int j) const { return levels_[j].omega; }
  bool coarsest_exact() const;

 private:
  struct Level {
    const BlockSparseMatrix* A = nullptr;
    BlockJacobiPreconditioner smoother;
    double omega = 0.0;
    const geometry::SparseMatrix* refinement = nullptr;  // from the next coarser level
    geometry::SparseMatrix restriction;                  // its transpose
  };
  class CoarsestSolver;

  void Cycle(int j, const Eigen::VectorXd& r, Eigen::VectorXd* x) const;

  MultigridOptions options_;
  std::vector<BlockSparseMatrix> coarse_;
  std::vector<Level> levels_;
  std::unique_ptr<CoarsestSolver> coarsest_;
};

// Adds `value` to the diagonal of every diagonal 3×3 block of `A` (which must hold them).
void AddToBlockDiagonal(double value, BlockSparseMatrix* A);

}  // namespace subflow::solver
