#include "solver/motion/multigrid_preconditioner.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <Eigen/SparseCholesky>

#include "core/error.h"
#include "solver/motion/row_product.h"

namespace subflow::solver {
namespace {

using Vector = Eigen::VectorXd;

// y = S x for a per-vertex operator S applied to interleaved (x, y, z) vectors.
Vector ApplyPerVertex(const geometry::SparseMatrix& S, const Vector& x) {
  const RowMajorColumns<3> y =
      RowParallelProduct<3>(S, Eigen::Map<const RowMajorColumns<3>>(x.data(), x.size() / 3, 3));
  return Eigen::Map<const Vector>(y.data(), y.size());
}

Vector Multiply(const BlockSparseMatrix& A, const Vector& x) {
  Vector y(x.size());
  MultiplySymmetric(A, x, &y);
  return y;
}

// λmax(D⁻¹A) by power iteration from a fixed rough start (the same estimate on every run):
// the largest eigenvalues belong to the most oscillating fields, which a smooth start
// would barely contain.
double LargestEigenvalue(const BlockSparseMatrix& A, const BlockJacobiPreconditioner& smoother, int iterations) {
  Vector x(3 * A.blocks());
  std::uint32_t state = 12345u;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    state = state * 1664525u + 1013904223u;  // a linear congruential sequence
    x(i) = (state >> 31) ? 1.0 : -1.0;
  }
  double lambda = 0.0;
  for (int k = 0; k < iterations; ++k) {
    const double norm = x.norm();
    if (!(norm > 0.0)) break;
    x /= norm;
    const Vector y = smoother.solve(Multiply(A, x));
    lambda = x.dot(y) > 0.0 ? y.norm() : lambda;
    x = y;
  }
  return lambda;
}

Eigen::SparseMatrix<double> ScalarForm(const BlockSparseMatrix& A) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(A.values.size());
  for (int v = 0; v < A.blocks(); ++v)
    for (int k = A.outer[v]; k < A.outer[v + 1]; ++k)
      for (int b = 0; b < 3; ++b)
        for (int a = 0; a < 3; ++a)
          entries.emplace_back(3 * A.row[k] + a, 3 * v + b, A.values[9 * static_cast<std::size_t>(k) + 3 * b + a]);
  Eigen::SparseMatrix<double> S(3 * A.blocks(), 3 * A.blocks());
  S.setFromTriplets(entries.begin(), entries.end());
  return S;
}

}  // namespace

// The coarsest level's exact solve: sparse Cholesky (AMD ordering) of its scalar form.
class MultigridPreconditioner::CoarsestSolver {
 public:
  explicit CoarsestSolver(const BlockSparseMatrix& A) {
    cholesky_.compute(ScalarForm(A));
    exact_ = cholesky_.info() == Eigen::Success;
  }
  bool exact() const { return exact_; }
  Vector Solve(const Vector& r) const { return cholesky_.solve(r); }

 private:
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower> cholesky_;
  bool exact_ = false;
};

MultigridPreconditioner::MultigridPreconditioner(const BlockSparseMatrix& fine, std::vector<BlockSparseMatrix> coarse,
                                                 std::vector<const geometry::SparseMatrix*> refinement,
                                                 const MultigridOptions& options)
    : options_(options), coarse_(std::move(coarse)) {
  if (coarse_.size() != refinement.size())
    ThrowError("multigrid", "levels", std::to_string(coarse_.size()) + " coarse matrices but " +
                                          std::to_string(refinement.size()) + " refinements");
  if (options_.sweeps < 1 || options_.power_iterations < 1 || !(options_.lambda_margin >= 1.0))
    ThrowError("multigrid", "options", "expected sweeps ≥ 1, power_iterations ≥ 1, lambda_margin ≥ 1");
  levels_.resize(coarse_.size() + 1);
  for (std::size_t j = 0; j < levels_.size(); ++j) {
    Level& level = levels_[j];
    level.A = j == 0 ? &fine : &coarse_[j - 1];
    if (j + 1 < levels_.size()) {
      const geometry::SparseMatrix& C = *refinement[j];
      if (C.rows() != level.A->blocks() || C.cols() != coarse_[j].blocks())
        ThrowError("multigrid", "refinement " + std::to_string(j),
                   std::to_string(C.rows()) + "×" + std::to_string(C.cols()) + ", expected " +
                       std::to_string(level.A->blocks()) + "×" + std::to_string(coarse_[j].blocks()));
      level.refinement = &C;
      level.restriction = C.transpose();
    }
  }
  coarsest_ = std::make_unique<CoarsestSolver>(*levels_.back().A);
  for (std::size_t j = 0; j < levels_.size(); ++j) {
    Level& level = levels_[j];
    const bool smoothed = j + 1 < levels_.size() || !coarsest_->exact();
    if (!smoothed) continue;
    level.smoother.FactorizeBlocks(*level.A);
    const double lambda = LargestEigenvalue(*level.A, level.smoother, options_.power_iterations);
    level.omega = lambda > 0.0 ? 4.0 / (3.0 * options_.lambda_margin * lambda) : 0.0;
  }
}

MultigridPreconditioner::~MultigridPreconditioner() = default;

bool MultigridPreconditioner::coarsest_exact() const { return coarsest_->exact(); }

Vector MultigridPreconditioner::solve(const Vector& r) const {
  Vector x;
  Cycle(0, r, &x);
  return x;
}

void MultigridPreconditioner::Cycle(int j, const Vector& r, Vector* x) const {
  const Level& level = levels_[j];
  const bool coarsest = j + 1 == static_cast<int>(levels_.size());
  if (coarsest && coarsest_->exact()) {
    *x = coarsest_->Solve(r);
    return;
  }
  auto sweep = [&] { *x += level.omega * level.smoother.solve(r - Multiply(*level.A, *x)); };
  *x = level.omega * level.smoother.solve(r);
  for (int s = 1; s < options_.sweeps; ++s) sweep();
  if (coarsest) {  // no exact solve: the smoother alone, symmetric as a whole
    for (int s = 0; s < options_.sweeps; ++s) sweep();
    return;
  }
  Vector correction;
  Cycle(j + 1, ApplyPerVertex(level.restriction, r - Multiply(*level.A, *x)), &correction);
  *x += ApplyPerVertex(*level.refinement, correction);
  for (int s = 0; s < options_.sweeps; ++s) sweep();
}

void AddToBlockDiagonal(double value, BlockSparseMatrix* A) {
  for (int v = 0; v < A->blocks(); ++v) {
    bool found = false;
    for (int k = A->outer[v]; k < A->outer[v + 1]; ++k) {
      if (A->row[k] != v) continue;
      for (int a = 0; a < 3; ++a) A->values[9 * static_cast<std::size_t>(k) + 4 * a] += value;
      found = true;
    }
    SUBFLOW_CHECK(found, "block matrix without a diagonal block");
  }
}

}  // namespace subflow::solver
