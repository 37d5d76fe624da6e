// The parallel sparse products of the normal-flow solver (solver/motion/row_product.h):
// A B and Aᵀ B agree with Eigen's products, and give the same bits on one thread as on
// many (the motion of a take does not depend on the machine's cores).
#include "solver/motion/row_product.h"

#include <random>
#include <vector>

#include <Eigen/SparseCore>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

namespace subflow::solver {
namespace {

// A tall random matrix like L (samples × control points, ~12 entries a row) and a right side.
struct Operands {
  geometry::SparseMatrix A;
  RowMajorColumns<3> B_rows;  // #rows × 3, for Aᵀ B
  RowMajorColumns<3> B_cols;  // #cols × 3, for A B
};

Operands MakeOperands(int rows, int cols) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int> column(0, cols - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (int r = 0; r < rows; ++r)
    for (int k = 0; k < 12; ++k) entries.emplace_back(r, column(random), value(random));
  Operands operands;
  operands.A.resize(rows, cols);
  operands.A.setFromTriplets(entries.begin(), entries.end());
  operands.A.makeCompressed();
  operands.B_rows = RowMajorColumns<3>::NullaryExpr(rows, 3, [&] { return value(random); });
  operands.B_cols = RowMajorColumns<3>::NullaryExpr(cols, 3, [&] { return value(random); });
  return operands;
}

TEST(RowProduct, ProductsAgreeWithEigensAndDoNotDependOnTheThreads) {
  // More rows than one chunk of the transposed product holds (several partial sums).
  const Operands o = MakeOperands(150000, 2000);
  const RowMajorColumns<3> product = RowParallelProduct<3>(o.A, o.B_cols);
  const RowMajorColumns<3> transposed = TransposeParallelProduct<3>(o.A, o.B_rows);
  const RowMajorColumns<3> eigen_product = o.A * o.B_cols;
  const RowMajorColumns<3> eigen_transposed = o.A.transpose() * o.B_rows;
  EXPECT_EQ(product, eigen_product);  // each row sums in A's order, as Eigen does
  ASSERT_EQ(transposed.rows(), 2000);
  EXPECT_LT((transposed - eigen_transposed).cwiseAbs().maxCoeff(), 1e-11 * eigen_transposed.cwiseAbs().maxCoeff());
  RowMajorColumns<3> single_product, single_transposed;
  {
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    single_product = RowParallelProduct<3>(o.A, o.B_cols);
    single_transposed = TransposeParallelProduct<3>(o.A, o.B_rows);
  }
  EXPECT_EQ(single_product, product);
  EXPECT_EQ(single_transposed, transposed);
}

TEST(RowProduct, TheTransposedProductOfAShortMatrixMatchesEigens) {
  const Operands o = MakeOperands(10, 4);
  const RowMajorColumns<3> transposed = TransposeParallelProduct<3>(o.A, o.B_rows);
  const RowMajorColumns<3> eigen_transposed = o.A.transpose() * o.B_rows;
  EXPECT_LT((transposed - eigen_transposed).cwiseAbs().maxCoeff(), 1e-14);
}

}  // namespace
}  // namespace subflow::solver
