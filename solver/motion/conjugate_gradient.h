// Preconditioned conjugate gradients for the symmetric positive definite normal equations of
// the motion solver: the textbook PCG iteration (as Eigen::ConjugateGradient, same stopping
// rule ‖b − A x‖ ≤ tolerance · ‖b‖), with the 3×3 block-Jacobi preconditioner and the
// sparse matrix–vector product run in parallel (TBB) — Eigen's sparse products use one
// core unless built with OpenMP, and the product is where the solver spends its time.
#pragma once

#include <Eigen/Core>
#include <Eigen/Sparse>

namespace subflow::solver {

struct ConjugateGradientResult {
  int iterations = 0;
  double relative_residual = 0.0;  // ‖b − A x‖ / ‖b‖ at exit (0 when b = 0)
};

// Solves A x = b, A symmetric positive definite (column-major; the full matrix, both
// triangles), unknowns interleaved (x, y, z) per vertex for the preconditioner. `x` holds
// the initial guess (its size must match) and receives the solution.
ConjugateGradientResult SolveConjugateGradient(const Eigen::SparseMatrix<double>& A,
                                               const Eigen::VectorXd& b, double tolerance,
                                               int max_iterations, Eigen::VectorXd* x);

}  // namespace subflow::solver
