#include "solver/motion/level_matrices.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::solver {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

// Block sums layout: xx xy xz yy yz zz; kSym[a][b] is the value of component (a, b).
constexpr int kSym[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};

template <typename Matrix>
Sparse Ones(const Matrix& matrix) {
  Sparse ones = matrix;
  for (int k = 0; k < ones.outerSize(); ++k)
    for (Sparse::InnerIterator it(ones, k); it; ++it) it.valueRef() = 1.0;
  return ones;
}

}  // namespace

int SymmetricPattern::Entry(int row, int column) const {
  const int* inner = pattern.innerIndexPtr();
  const int* first = inner + pattern.outerIndexPtr()[column];
  const int* last = inner + pattern.outerIndexPtr()[column + 1];
  const int* found = std::lower_bound(first, last, row);
  return found != last && *found == row ? static_cast<int>(found - inner) : -1;
}

SymmetricPattern MakeSymmetricPattern(const Sparse& structure) {
  SymmetricPattern result;
  // A transposed copy sorts the inner indices (the lookups bisect).
  const Sparse transposed = structure.transpose();
  result.pattern = transposed.transpose();
  result.pattern.makeCompressed();
  const int* outer = result.pattern.outerIndexPtr();
  const int* inner = result.pattern.innerIndexPtr();
  result.mirror.resize(static_cast<std::size_t>(result.pattern.nonZeros()));
  tbb::parallel_for(0, static_cast<int>(result.pattern.cols()), [&](int column) {
    for (int e = outer[column]; e < outer[column + 1]; ++e) {
      result.mirror[e] = result.Entry(column, inner[e]);
      SUBFLOW_CHECK(result.mirror[e] >= 0, "pattern is not symmetric");
    }
  });
  return result;
}

geometry::SparseMatrix CoarseningMap(const SymmetricPattern& fine, const geometry::SparseMatrix& refinement,
                                     SymmetricPattern* coarse) {
  const Sparse C = Ones(refinement);
  *coarse = MakeSymmetricPattern(Sparse(C.transpose() * Sparse(Ones(fine.pattern) * C)));
  const int* outer = fine.pattern.outerIndexPtr();
  const int* inner = fine.pattern.innerIndexPtr();
  const int* C_outer = refinement.outerIndexPtr();
  const int* C_inner = refinement.innerIndexPtr();
  const double* C_values = refinement.valuePtr();
  std::vector<Eigen::Triplet<double>> triplets;
  for (int j = 0; j < fine.pattern.cols(); ++j)
    for (int e = outer[j]; e < outer[j + 1]; ++e) {
      const int r = inner[e];
      if (r > j) continue;
      // Unordered fine pair {r, j}: its block reaches coarse (I, J) for I a parent of r and
      // J of j (and the mirrored (J, I)); stored once, on the upper coarse entry.
      for (int p = C_outer[r]; p < C_outer[r + 1]; ++p)
        for (int q = C_outer[j]; q < C_outer[j + 1]; ++q) {
          const int I = C_inner[p], J = C_inner[q];
          if (r == j && I > J) continue;  // a diagonal fine block: (I, J) and (J, I) once
          const double weight = C_values[p] * C_values[q] * (r != j && I == J ? 2.0 : 1.0);
          const int E = coarse->UpperEntry(I, J);
          SUBFLOW_CHECK(E >= 0, "coarse pattern misses an entry");
          triplets.emplace_back(E, e, weight);
        }
    }
  geometry::SparseMatrix map(coarse->entries(), fine.entries());
  map.setFromTriplets(triplets.begin(), triplets.end());
  return map;
}

std::vector<double> CoarsenBlockSums(const geometry::SparseMatrix& map, const std::vector<double>& fine_sums) {
  SUBFLOW_CHECK(fine_sums.size() == 6 * static_cast<std::size_t>(map.cols()), "block sums of another level");
  std::vector<double> sums(6 * static_cast<std::size_t>(map.rows()), 0.0);
  tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(map.rows()), 1024),
                    [&](const tbb::blocked_range<int>& range) {
    for (int E = range.begin(); E < range.end(); ++E) {
      double* sum = sums.data() + 6 * static_cast<std::size_t>(E);
      for (int k = map.outerIndexPtr()[E]; k < map.outerIndexPtr()[E + 1]; ++k) {
        const double w = map.valuePtr()[k];
        const double* fine = fine_sums.data() + 6 * static_cast<std::size_t>(map.innerIndexPtr()[k]);
        for (int i = 0; i < 6; ++i) sum[i] += w * fine[i];
      }
    }
  });
  return sums;
}

LevelMatrix MakeLevelMatrix(const SymmetricPattern& data_pattern, const Sparse& regularizer3) {
  const int vertices = static_cast<int>(data_pattern.pattern.cols());
  SUBFLOW_CHECK(regularizer3.rows() == 3 * vertices && regularizer3.cols() == 3 * vertices,
                "regularizer of another level");
  std::vector<Eigen::Triplet<double>> blocks;
  blocks.reserve(9 * static_cast<std::size_t>(data_pattern.entries()));
  for (int j = 0; j < vertices; ++j)
    for (Sparse::InnerIterator it(data_pattern.pattern, j); it; ++it)
      for (int b = 0; b < 3; ++b)
        for (int a = 0; a < 3; ++a) blocks.emplace_back(3 * static_cast<int>(it.row()) + a, 3 * j + b, 0.0);
  Sparse data(3 * vertices, 3 * vertices);
  data.setFromTriplets(blocks.begin(), blocks.end());
  LevelMatrix level;
  level.regularizer = data + regularizer3;  // the union pattern; 0 where only data
  level.regularizer.makeCompressed();
  level.data_slot.resize(static_cast<std::size_t>(level.regularizer.nonZeros()));
  level.diagonal_slot.assign(3 * static_cast<std::size_t>(vertices), -1);
  for (int column = 0; column < 3 * vertices; ++column)
    for (int k = level.regularizer.outerIndexPtr()[column]; k < level.regularizer.outerIndexPtr()[column + 1]; ++k) {
      const int row = level.regularizer.innerIndexPtr()[k];
      const int r = row / 3, j = column / 3, a = row % 3, b = column % 3;
      const int e = data_pattern.UpperEntry(r, j);
      level.data_slot[k] = e < 0 ? -1 : 6 * e + kSym[a][b];
      if (row == column) level.diagonal_slot[row] = level.data_slot[k];
    }
  level.blocks = MakeBlockSparse(level.regularizer);
  level.block_slot.resize(level.data_slot.size());
  for (int j = 0; j < vertices; ++j)
    for (int b = 0; b < 3; ++b) {
      const int column = 3 * j + b;
      int block = level.blocks.outer[j];
      for (int k = level.regularizer.outerIndexPtr()[column]; k < level.regularizer.outerIndexPtr()[column + 1]; ++k) {
        const int row = level.regularizer.innerIndexPtr()[k];
        while (level.blocks.row[block] != row / 3) ++block;
        level.block_slot[k] = 9 * block + 3 * b + row % 3;
      }
    }
  level.blocks.values = {};  // the structure is what is kept
  return level;
}

double DataStiffness(const LevelMatrix& level, const std::vector<double>& sums) {
  Eigen::VectorXd diagonal(static_cast<Eigen::Index>(level.diagonal_slot.size()));
  for (Eigen::Index i = 0; i < diagonal.size(); ++i)
    diagonal(i) = level.diagonal_slot[i] < 0 ? 0.0 : sums[level.diagonal_slot[i]];
  return diagonal.size() > 0 ? diagonal.sum() / diagonal.size() : 0.0;
}

BlockSparseMatrix AssembleLevelBlocks(const LevelMatrix& level, const std::vector<double>& sums, double stiffness) {
  BlockSparseMatrix A;
  A.outer = level.blocks.outer;
  A.row = level.blocks.row;
  A.values.assign(9 * level.blocks.row.size(), 0.0);  // entries in neither pattern stay 0
  const double* regularizer = level.regularizer.valuePtr();
  const int nonzeros = static_cast<int>(level.regularizer.nonZeros());
  tbb::parallel_for(tbb::blocked_range<int>(0, nonzeros, 16384), [&](const tbb::blocked_range<int>& range) {
    for (int k = range.begin(); k < range.end(); ++k) {
      const int slot = level.data_slot[k];
      const double value = stiffness * regularizer[k];
      A.values[level.block_slot[k]] = slot < 0 ? value : sums[slot] + value;
    }
  });
  return A;
}

Sparse AssembleLevelMatrix(const LevelMatrix& level, const std::vector<double>& sums, double stiffness) {
  Sparse A = level.regularizer;
  double* values = A.valuePtr();
  const int nonzeros = static_cast<int>(A.nonZeros());
  tbb::parallel_for(tbb::blocked_range<int>(0, nonzeros, 16384), [&](const tbb::blocked_range<int>& range) {
    for (int k = range.begin(); k < range.end(); ++k) {
      const int slot = level.data_slot[k];
      const double regularizer = stiffness * values[k];
      values[k] = slot < 0 ? regularizer : sums[slot] + regularizer;
    }
  });
  return A;
}

}  // namespace subflow::solver
