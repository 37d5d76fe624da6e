// The V-cycle preconditioner of the normal-flow CG (multigrid_preconditioner.h) on level
// systems built as the motion solver builds them (level_matrices.h): a symmetric positive
// definite map, and CG with it reaches the block-Jacobi CG's solution in a fraction of the
// iterations.
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/icosphere.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/loop_operators.h"
#include "solver/motion/conjugate_gradient.h"
#include "solver/motion/level_matrices.h"
#include "solver/motion/multigrid_preconditioner.h"

namespace subflow::solver {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

Sparse Kron3(const geometry::SparseMatrix& matrix) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int r = 0; r < matrix.outerSize(); ++r)
    for (geometry::SparseMatrix::InnerIterator it(matrix, r); it; ++it)
      for (int a = 0; a < 3; ++a) entries.emplace_back(3 * it.row() + a, 3 * it.col() + a, it.value());
  Sparse result(3 * matrix.rows(), 3 * matrix.cols());
  result.setFromTriplets(entries.begin(), entries.end());
  return result;
}

// Levels 0–3 over an icosphere: data only on the finest level's diagonal blocks (one
// gradient direction per control point, the aperture problem: rank 1 each), carried to
// the coarser levels by Cᵀ · C; regularizer w (1/h_l)⁴ UᵀU + β I with h_l doubling per
// level; the CG matrix of level 3 and the coarser matrices as the solver weights them.
struct LevelSystems {
  static constexpr int kFinest = 3;
  geometry::TriangleMesh base = geometry::MakeIcosphere(1, 1.0);
  geometry::LoopHierarchy hierarchy{base.F, base.vertex_count(), kFinest};
  std::vector<SymmetricPattern> pattern = std::vector<SymmetricPattern>(kFinest + 1);
  std::vector<LevelMatrix> level = std::vector<LevelMatrix>(kFinest + 1);
  std::vector<std::vector<double>> sums = std::vector<std::vector<double>>(kFinest + 1);
  BlockSparseMatrix fine;
  std::vector<BlockSparseMatrix> coarse;
  std::vector<const geometry::SparseMatrix*> refinement;

  LevelSystems() {
    const geometry::SparseMatrix U = geometry::UmbrellaLaplacian(hierarchy.Topology(kFinest));
    pattern[kFinest] = MakeSymmetricPattern(Sparse(geometry::SparseMatrix(U.transpose() * U)));
    std::mt19937 random(11);
    std::normal_distribution<double> normal(0.0, 1.0);
    sums[kFinest].assign(6 * static_cast<std::size_t>(pattern[kFinest].entries()), 0.0);
    for (int v = 0; v < hierarchy.VertexCount(kFinest); ++v) {
      const Eigen::Vector3d g(normal(random), normal(random), normal(random));
      const int e = pattern[kFinest].Entry(v, v);
      const double values[6] = {g(0) * g(0), g(0) * g(1), g(0) * g(2), g(1) * g(1), g(1) * g(2), g(2) * g(2)};
      for (int i = 0; i < 6; ++i) sums[kFinest][6 * e + i] = values[i];
    }
    for (int l = kFinest - 1; l >= 0; --l)
      sums[l] = CoarsenBlockSums(CoarseningMap(pattern[l + 1], hierarchy.Refinement(l), &pattern[l]), sums[l + 1]);
    for (int l = 0; l <= kFinest; ++l) {
      const geometry::SparseMatrix Ul = geometry::UmbrellaLaplacian(hierarchy.Topology(l));
      Sparse identity(3 * Ul.rows(), 3 * Ul.rows());
      identity.setIdentity();
      Sparse regularizer = 0.05 * std::pow(16.0, l) * Kron3(geometry::SparseMatrix(Ul.transpose() * Ul)) +
                           1e-3 * identity;
      regularizer.makeCompressed();
      level[l] = MakeLevelMatrix(pattern[l], regularizer);
    }
    const double stiffness = DataStiffness(level[kFinest], sums[kFinest]);
    fine = AssembleLevelBlocks(level[kFinest], sums[kFinest], stiffness);
    double scale = stiffness;
    for (int l = kFinest - 1; l >= 0; --l) {
      scale *= 4.0;
      coarse.push_back(AssembleLevelBlocks(level[l], sums[l], scale));
      refinement.push_back(&hierarchy.Refinement(l));
    }
  }
};

Eigen::VectorXd RandomVector(Eigen::Index size, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd v(size);
  for (Eigen::Index i = 0; i < size; ++i) v(i) = normal(random);
  return v;
}

TEST(MultigridPreconditioner, IsASymmetricPositiveDefiniteMap) {
  const LevelSystems systems;
  const MultigridPreconditioner multigrid(systems.fine, systems.coarse, systems.refinement);
  ASSERT_EQ(multigrid.levels(), 4);
  EXPECT_TRUE(multigrid.coarsest_exact());
  for (int j = 0; j + 1 < multigrid.levels(); ++j) EXPECT_GT(multigrid.damping(j), 0.0);
  const Eigen::Index size = 3 * systems.fine.blocks();
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const Eigen::VectorXd u = RandomVector(size, seed), v = RandomVector(size, 100 + seed);
    const Eigen::VectorXd Mu = multigrid.solve(u), Mv = multigrid.solve(v);
    EXPECT_NEAR(u.dot(Mv), v.dot(Mu), 1e-10 * u.norm() * Mv.norm());
    EXPECT_GT(v.dot(Mv), 0.0);
    EXPECT_GT(u.dot(Mu), 0.0);
  }
}

TEST(MultigridPreconditioner, CgReachesTheSameSolutionInAFractionOfTheIterations) {
  const LevelSystems systems;
  const MultigridPreconditioner multigrid(systems.fine, systems.coarse, systems.refinement);
  const Eigen::VectorXd b = RandomVector(3 * systems.fine.blocks(), 7);
  Eigen::VectorXd jacobi = Eigen::VectorXd::Zero(b.size()), cycled = Eigen::VectorXd::Zero(b.size());
  const ConjugateGradientResult plain = SolveConjugateGradient(systems.fine, b, 1e-9, 20000, &jacobi);
  const ConjugateGradientResult fast = SolveConjugateGradient(systems.fine, b, 1e-9, 20000, &cycled, &multigrid);
  std::printf("block Jacobi: %d iterations; V-cycle: %d iterations (%d unknowns)\n", plain.iterations,
              fast.iterations, static_cast<int>(b.size()));
  ASSERT_LE(plain.relative_residual, 1e-9);
  ASSERT_LE(fast.relative_residual, 1e-9);
  EXPECT_LT((cycled - jacobi).norm(), 1e-6 * jacobi.norm());
  EXPECT_LT(5 * fast.iterations, plain.iterations);
}

TEST(MultigridPreconditioner, RefusesRefinementsOfTheWrongSize) {
  const LevelSystems systems;
  std::vector<const geometry::SparseMatrix*> swapped = systems.refinement;
  std::swap(swapped[0], swapped[1]);
  EXPECT_THROW(MultigridPreconditioner(systems.fine, systems.coarse, swapped), Error);
}

}  // namespace
}  // namespace subflow::solver
