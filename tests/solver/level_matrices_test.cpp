// The level matrices of the normal-flow solver on fixed patterns (level_matrices.h): the
// precomputed coarsening map gives C(i)ᵀ N C(i) (checked against dense products), and the
// assembled CG matrix is data + κ · regularizer on the union pattern.
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "geometry/icosphere.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/loop_operators.h"
#include "solver/motion/level_matrices.h"

namespace subflow::solver {
namespace {

using Sparse = Eigen::SparseMatrix<double>;
constexpr int kSym[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};

// Random symmetric 3×3 blocks on the upper entries of `pattern` (6 values each).
std::vector<double> RandomBlockSums(const SymmetricPattern& pattern, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<double> sums(6 * static_cast<std::size_t>(pattern.entries()), 0.0);
  for (int j = 0; j < pattern.pattern.cols(); ++j)
    for (int e = pattern.pattern.outerIndexPtr()[j]; e < pattern.pattern.outerIndexPtr()[j + 1]; ++e)
      if (pattern.pattern.innerIndexPtr()[e] <= j)
        for (int i = 0; i < 6; ++i) sums[6 * e + i] = value(random);
  return sums;
}

// The dense 3#V matrix of block sums (blocks (r, c) and (c, r) both from the upper entry).
Eigen::MatrixXd Dense(const SymmetricPattern& pattern, const std::vector<double>& sums) {
  const int vertices = static_cast<int>(pattern.pattern.cols());
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * vertices, 3 * vertices);
  for (int j = 0; j < vertices; ++j)
    for (Sparse::InnerIterator it(pattern.pattern, j); it; ++it) {
      const int r = static_cast<int>(it.row());
      const int e = pattern.UpperEntry(r, j);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) dense(3 * r + a, 3 * j + b) = sums[6 * e + kSym[a][b]];
    }
  return dense;
}

Eigen::MatrixXd Kron3(const geometry::SparseMatrix& matrix) {
  const Eigen::MatrixXd scalar = Eigen::MatrixXd(matrix);
  Eigen::MatrixXd result = Eigen::MatrixXd::Zero(3 * scalar.rows(), 3 * scalar.cols());
  for (int r = 0; r < scalar.rows(); ++r)
    for (int c = 0; c < scalar.cols(); ++c)
      for (int a = 0; a < 3; ++a) result(3 * r + a, 3 * c + a) = scalar(r, c);
  return result;
}

struct TwoLevels {
  geometry::TriangleMesh base = geometry::MakeIcosphere(0, 1.0);
  geometry::LoopHierarchy hierarchy{base.F, base.vertex_count(), 1};
  // Level 1's pattern: that of the umbrella operator's Gram matrix (2-rings).
  SymmetricPattern fine;
  TwoLevels() {
    const geometry::SparseMatrix U = geometry::UmbrellaLaplacian(hierarchy.Topology(1));
    fine = MakeSymmetricPattern(Sparse(geometry::SparseMatrix(U.transpose() * U)));
  }
};

TEST(LevelMatrices, CoarseningMapGivesTheTripleProductOfTheRefinement) {
  const TwoLevels levels;
  SymmetricPattern coarse;
  const geometry::SparseMatrix map = CoarseningMap(levels.fine, levels.hierarchy.Refinement(0), &coarse);
  EXPECT_EQ(coarse.pattern.cols(), levels.hierarchy.VertexCount(0));
  const std::vector<double> fine_sums = RandomBlockSums(levels.fine, 7);
  const Eigen::MatrixXd C3 = Kron3(levels.hierarchy.Refinement(0));
  const Eigen::MatrixXd expected = C3.transpose() * Dense(levels.fine, fine_sums) * C3;
  const Eigen::MatrixXd coarsened = Dense(coarse, CoarsenBlockSums(map, fine_sums));
  EXPECT_GT(expected.norm(), 1.0);
  EXPECT_LT((coarsened - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
}

TEST(LevelMatrices, AssemblyIsDataPlusStiffnessTimesRegularizer) {
  const TwoLevels levels;
  // A regularizer with entries outside the data pattern: the 4-ring Gram matrix of U².
  const geometry::SparseMatrix U = geometry::UmbrellaLaplacian(levels.hierarchy.Topology(1));
  const geometry::SparseMatrix U2 = U * U;
  const Eigen::MatrixXd regularizer = Kron3(geometry::SparseMatrix(U2.transpose() * U2)) +
                                      0.01 * Eigen::MatrixXd::Identity(3 * U.rows(), 3 * U.rows());
  const Sparse regularizer3 = regularizer.sparseView();
  const LevelMatrix level = MakeLevelMatrix(levels.fine, regularizer3);
  const std::vector<double> sums = RandomBlockSums(levels.fine, 11);
  const Eigen::MatrixXd data = Dense(levels.fine, sums);
  const double stiffness = 2.5;
  const Eigen::MatrixXd assembled = Eigen::MatrixXd(AssembleLevelMatrix(level, sums, stiffness));
  EXPECT_LT((assembled - (data + stiffness * regularizer)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GT(level.regularizer.nonZeros(), 9 * levels.fine.entries());  // the union is larger
  EXPECT_NEAR(DataStiffness(level, sums), data.diagonal().mean(), 1e-12);

  // Assembled straight into blocks: the block form of the scalar assembly, to the bit,
  // and conjugate gradients on it take the same iterates.
  const BlockSparseMatrix blocks = AssembleLevelBlocks(level, sums, stiffness);
  const BlockSparseMatrix reference = MakeBlockSparse(AssembleLevelMatrix(level, sums, stiffness));
  EXPECT_EQ(blocks.outer, reference.outer);
  EXPECT_EQ(blocks.row, reference.row);
  EXPECT_EQ(blocks.values, reference.values);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(regularizer.rows(), -1.0, 2.0);
  Eigen::VectorXd from_blocks = Eigen::VectorXd::Zero(b.size()), from_scalar = from_blocks;
  const ConjugateGradientResult cg = SolveConjugateGradient(blocks, b, 1e-10, 200, &from_blocks);
  SolveConjugateGradient(Sparse(AssembleLevelMatrix(level, sums, stiffness)), b, 1e-10, 200, &from_scalar);
  EXPECT_GT(cg.iterations, 3);
  EXPECT_EQ(from_blocks, from_scalar);
  EXPECT_LT((assembled * from_blocks - b).norm(), 1e-8 * b.norm());
}

}  // namespace
}  // namespace subflow::solver
