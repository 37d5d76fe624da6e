// Preconditioned conjugate gradients for the symmetric positive definite normal equations of
// the motion solver: the textbook PCG iteration (as Eigen::ConjugateGradient, same stopping
// rule ‖b − A x‖ ≤ tolerance · ‖b‖), with the 3×3 block-Jacobi preconditioner and the
// sparse matrix–vector product run in parallel (TBB) — Eigen's sparse products use one
// core unless built with OpenMP, and the product is where the solver spends its time.
// The product runs on 3×3 blocks (one index per block instead of one per value, three
// contiguous x values per block): the matrix is converted once per solve.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

namespace subflow::solver {

// A square sparse matrix of 3×3 blocks (block compressed columns): for block column v, the
// blocks outer[v] … outer[v+1]−1 with block rows row[k] ascending and values[9k …] column-
// major (entry (a, b) of block k at 9k + 3b + a). Entries absent from the scalar matrix are 0.
struct BlockSparseMatrix {
  std::vector<int> outer, row;
  std::vector<double> values;
  int blocks() const { return static_cast<int>(outer.size()) - 1; }
};

// The block form of `A` (3#V square, column-major).
BlockSparseMatrix MakeBlockSparse(const Eigen::SparseMatrix<double>& A);

// y = A x for symmetric A: y_j is column j's dot product with x, summed in the order of
// the column's rows (the block form and the scalar form give the same sums).
void MultiplySymmetric(const BlockSparseMatrix& A, const Eigen::VectorXd& x, Eigen::VectorXd* y);
void MultiplySymmetric(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& x, Eigen::VectorXd* y);

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
// The same for A in block form (the same iterates as its scalar form, to the bit), with the
// block-Jacobi preconditioner, or with `multigrid` (multigrid_preconditioner.h: a V-cycle
// over the coarser levels, built for this A) when it is given.
class MultigridPreconditioner;
ConjugateGradientResult SolveConjugateGradient(const BlockSparseMatrix& A, const Eigen::VectorXd& b,
                                               double tolerance, int max_iterations, Eigen::VectorXd* x,
                                               const MultigridPreconditioner* multigrid = nullptr);

}  // namespace subflow::solver
