#include "solver/motion/conjugate_gradient.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "solver/motion/block_jacobi_preconditioner.h"
#include "solver/motion/multigrid_preconditioner.h"

namespace subflow::solver {
BlockSparseMatrix MakeBlockSparse(const Eigen::SparseMatrix<double>& A) {
  SUBFLOW_CHECK(A.rows() == A.cols() && A.rows() % 3 == 0, "block sparse: 3#V square matrix expected");
  const int blocks = static_cast<int>(A.cols() / 3);
  BlockSparseMatrix result;
  result.outer.assign(blocks + 1, 0);
  std::vector<std::vector<int>> rows(blocks);
  tbb::parallel_for(0, blocks, [&](int v) {
    for (int b = 0; b < 3; ++b)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, 3 * v + b); it; ++it)
        rows[v].push_back(static_cast<int>(it.row() / 3));
    std::sort(rows[v].begin(), rows[v].end());
    rows[v].erase(std::unique(rows[v].begin(), rows[v].end()), rows[v].end());
  });
  for (int v = 0; v < blocks; ++v) result.outer[v + 1] = result.outer[v] + static_cast<int>(rows[v].size());
  result.row.resize(result.outer.back());
  result.values.assign(9 * static_cast<std::size_t>(result.outer.back()), 0.0);
  tbb::parallel_for(0, blocks, [&](int v) {
    std::copy(rows[v].begin(), rows[v].end(), result.row.begin() + result.outer[v]);
    for (int b = 0; b < 3; ++b) {
      int k = result.outer[v];
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, 3 * v + b); it; ++it) {
        while (result.row[k] != it.row() / 3) ++k;
        result.values[9 * static_cast<std::size_t>(k) + 3 * b + it.row() % 3] = it.value();
      }
    }
  });
  return result;
}

void MultiplySymmetric(const BlockSparseMatrix& A, const Eigen::VectorXd& x, Eigen::VectorXd* y) {
  const int* outer = A.outer.data();
  const int* row = A.row.data();
  const double* values = A.values.data();
  const double* in = x.data();
  double* out = y->data();
  tbb::parallel_for(tbb::blocked_range<int>(0, A.blocks(), 256), [&](const tbb::blocked_range<int>& range) {
    for (int v = range.begin(); v < range.end(); ++v) {
      double y0 = 0.0, y1 = 0.0, y2 = 0.0;
      for (int k = outer[v]; k < outer[v + 1]; ++k) {
        const double* block = values + 9 * static_cast<std::size_t>(k);
        const double* xu = in + 3 * static_cast<std::size_t>(row[k]);
        for (int a = 0; a < 3; ++a) {  // rows 3u + a in ascending order, as in the scalar form
          y0 += block[a] * xu[a];
          y1 += block[3 + a] * xu[a];
          y2 += block[6 + a] * xu[a];
        }
      }
      out[3 * v] = y0;
      out[3 * v + 1] = y1;
      out[3 * v + 2] = y2;
    }
  });
}

void MultiplySymmetric(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& x, Eigen::VectorXd* y) {
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* values = A.valuePtr();
  const int* nonzeros = A.innerNonZeroPtr();
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, A.outerSize(), 512),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
    for (Eigen::Index j = range.begin(); j < range.end(); ++j) {
      const int begin = outer[j], end = nonzeros ? begin + nonzeros[j] : outer[j + 1];
      double sum = 0.0;
      for (int k = begin; k < end; ++k) sum += values[k] * x[inner[k]];
      (*y)[j] = sum;
    }
  });
}

ConjugateGradientResult SolveConjugateGradient(const Eigen::SparseMatrix<double>& A,
                                               const Eigen::VectorXd& b, double tolerance,
                                               int max_iterations, Eigen::VectorXd* x) {
  SUBFLOW_CHECK(A.rows() == A.cols() && A.rows() == b.size() && x->size() == b.size(),
                "conjugate gradients: sizes differ");
  return SolveConjugateGradient(MakeBlockSparse(A), b, tolerance, max_iterations, x);
}

namespace {

// The PCG iteration for any preconditioner with Eigen's solve(r) → z.
template <typename Preconditioner>
ConjugateGradientResult Iterate(const BlockSparseMatrix& blocks, const Preconditioner& preconditioner,
                                const Eigen::VectorXd& b, double tolerance, int max_iterations, Eigen::VectorXd* x) {
  ConjugateGradientResult result;
  const double b_norm = b.norm();
  Eigen::VectorXd r(b.size()), Ap(b.size());
  MultiplySymmetric(blocks, *x, &Ap);
  r = b - Ap;
  const double threshold = tolerance * b_norm;
  double r_norm = r.norm();
  Eigen::VectorXd z = preconditioner.solve(r);
  Eigen::VectorXd p = z;
  double rz = r.dot(z);
  while (r_norm > threshold && result.iterations < max_iterations) {
    MultiplySymmetric(blocks, p, &Ap);
    const double alpha = rz / p.dot(Ap);
    *x += alpha * p;
    r -= alpha * Ap;
    r_norm = r.norm();
    ++result.iterations;
    if (r_norm <= threshold) break;
    z = preconditioner.solve(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  result.relative_residual = r_norm / b_norm;
  return result;
}

}  // namespace

ConjugateGradientResult SolveConjugateGradient(const BlockSparseMatrix& blocks, const Eigen::VectorXd& b,
                                               double tolerance, int max_iterations, Eigen::VectorXd* x,
                                               const MultigridPreconditioner* multigrid) {
  SUBFLOW_CHECK(3 * static_cast<Eigen::Index>(blocks.blocks()) == b.size() && x->size() == b.size(),
                "conjugate gradients: sizes differ");
  if (b.norm() == 0.0) {
    x->setZero();
    return {};
  }
  if (multigrid) {
    // A V-cycle whose smoothing diverged (ω from an estimate of λmax too low) is not a
    // positive definite preconditioner: the iteration can stall or blow up. Then the
    // solve is done again from the same start with block Jacobi.
    const Eigen::VectorXd start = *x;
    const ConjugateGradientResult result = Iterate(blocks, *multigrid, b, tolerance, max_iterations, x);
    if (result.relative_residual <= tolerance && x->allFinite()) return result;
    *x = start;
  }
  BlockJacobiPreconditioner preconditioner;
  preconditioner.FactorizeBlocks(blocks);
  return Iterate(blocks, preconditioner, b, tolerance, max_iterations, x);
}

}  // namespace subflow::solver
