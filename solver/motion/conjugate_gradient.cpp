#include "solver/motion/conjugate_gradient.h"

#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "solver/motion/block_jacobi_preconditioner.h"

namespace subflow::solver {
namespace {

// y = A x for symmetric A: column j of A is row j, so each y_j is one column's dot product.
void Multiply(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& x, Eigen::VectorXd* y) {
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

}  // namespace

ConjugateGradientResult SolveConjugateGradient(const Eigen::SparseMatrix<double>& A,
                                               const Eigen::VectorXd& b, double tolerance,
                                               int max_iterations, Eigen::VectorXd* x) {
  SUBFLOW_CHECK(A.rows() == A.cols() && A.rows() == b.size() && x->size() == b.size(),
                "conjugate gradients: sizes differ");
  ConjugateGradientResult result;
  const double b_norm = b.norm();
  if (b_norm == 0.0) {
    x->setZero();
    return result;
  }
  const BlockJacobiPreconditioner preconditioner(A);
  Eigen::VectorXd r(b.size()), Ap(b.size());
  Multiply(A, *x, &Ap);
  r = b - Ap;
  const double threshold = tolerance * b_norm;
  double r_norm = r.norm();
  Eigen::VectorXd z = preconditioner.solve(r);
  Eigen::VectorXd p = z;
  double rz = r.dot(z);
  while (r_norm > threshold && result.iterations < max_iterations) {
    Multiply(A, p, &Ap);
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

}  // namespace subflow::solver
