// A 3×3 block-diagonal (block Jacobi) preconditioner for Eigen's iterative solvers, for
// systems whose unknowns are 3D vectors interleaved as (x, y, z) per vertex: index 3v + a.
// Each normal-flow constraint couples the three components of a sample's motion through
// g gᵀ (rank 1; rank 2 summed over the views of a sample), so the 3×3 diagonal blocks are
// strongly anisotropic and the scalar diagonal (Eigen::DiagonalPreconditioner) is a poor
// approximation of them. Blocks are inverted exactly (LDLᵀ); a block that is not positive
// definite falls back to the inverse of its diagonal (1 where the diagonal is ≤ 0).
//
// Interface of Eigen's preconditioners (analyzePattern / factorize / compute / solve /
// info), usable as Eigen::ConjugateGradient<Matrix, UpLo, BlockJacobiPreconditioner>.
#pragma once

#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Sparse>

namespace subflow::solver {

class BlockJacobiPreconditioner {
 public:
  using Scalar = double;
  using StorageIndex = int;

  BlockJacobiPreconditioner() = default;
  template <typename Matrix>
  explicit BlockJacobiPreconditioner(const Matrix& matrix) {
    compute(matrix);
  }

  template <typename Matrix>
  BlockJacobiPreconditioner& analyzePattern(const Matrix&) {
    return *this;
  }

  // Requires a square matrix of size 3·#blocks (column-major or row-major sparse).
  template <typename Matrix>
  BlockJacobiPreconditioner& factorize(const Matrix& matrix) {
    const Eigen::Index blocks = matrix.rows() / 3;
    inverse_.assign(static_cast<std::size_t>(blocks), Eigen::Matrix3d::Zero());
    std::vector<Eigen::Matrix3d> diagonal(static_cast<std::size_t>(blocks), Eigen::Matrix3d::Zero());
    for (Eigen::Index outer = 0; outer < matrix.outerSize(); ++outer)
      for (typename Matrix::InnerIterator it(matrix, outer); it; ++it)
        if (it.row() / 3 == it.col() / 3)
          diagonal[static_cast<std::size_t>(it.row() / 3)](it.row() % 3, it.col() % 3) = it.value();
    for (std::size_t v = 0; v < diagonal.size(); ++v) Invert(diagonal[v], &inverse_[v]);
    return *this;
  }

  // From a matrix in block form (conjugate_gradient.h): the same inverses as factorize of
  // its scalar form.
  template <typename Blocks>
  BlockJacobiPreconditioner& FactorizeBlocks(const Blocks& blocks) {
    inverse_.assign(static_cast<std::size_t>(blocks.blocks()), Eigen::Matrix3d::Zero());
    for (int v = 0; v < blocks.blocks(); ++v) {
      Eigen::Matrix3d diagonal = Eigen::Matrix3d::Zero();  // column-major, as the block values
      for (int k = blocks.outer[v]; k < blocks.outer[v + 1]; ++k)
        if (blocks.row[k] == v)
          diagonal = Eigen::Map<const Eigen::Matrix3d>(blocks.values.data() + 9 * static_cast<std::size_t>(k));
      Invert(diagonal, &inverse_[static_cast<std::size_t>(v)]);
    }
    return *this;
  }

  template <typename Matrix>
  BlockJacobiPreconditioner& compute(const Matrix& matrix) {
    return factorize(matrix);
  }

  template <typename Rhs>
  Eigen::VectorXd solve(const Rhs& b) const {
    Eigen::VectorXd x(b.size());
    for (std::size_t v = 0; v < inverse_.size(); ++v)
      x.segment<3>(3 * static_cast<Eigen::Index>(v)) =
          inverse_[v] * b.template segment<3>(3 * static_cast<Eigen::Index>(v));
    return x;
  }

  Eigen::ComputationInfo info() const { return Eigen::Success; }

 private:
  static void Invert(const Eigen::Matrix3d& block, Eigen::Matrix3d* inverse);

  std::vector<Eigen::Matrix3d> inverse_;
};

inline void BlockJacobiPreconditioner::Invert(const Eigen::Matrix3d& block,
                                              Eigen::Matrix3d* inverse) {
  const double scale = block.diagonal().cwiseAbs().maxCoeff();
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(block);
  if (scale > 0.0 && ldlt.info() == Eigen::Success &&
      (ldlt.vectorD().array() > 1e-12 * scale).all()) {
    *inverse = ldlt.solve(Eigen::Matrix3d::Identity());
    return;
  }
  inverse->setZero();
  for (int a = 0; a < 3; ++a) (*inverse)(a, a) = block(a, a) > 0.0 ? 1.0 / block(a, a) : 1.0;
}

}  // namespace subflow::solver
