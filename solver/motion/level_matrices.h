// The normal matrices of the normal-flow solver's levels (normal_flow_solver.h) on sparsity
// patterns fixed at construction, so that a solve only fills values.
//
// Data part. The data matrix of level i is a symmetric matrix of 3×3 blocks, one per entry
// (r, c) of a symmetric vertex pattern, and every block is itself symmetric (a weighted
// sum of the samples' g gᵀ). It is kept as 6 values per UPPER pattern entry (r ≤ c):
// xx xy xz yy yz zz ("block sums"). The finest estimated level's sums are accumulated from
// the samples (NormalFlowSolver::DataSums); a coarser level's are a fixed linear map of
// the finer level's, P_iᵀ N P_i = C(i)ᵀ (P_{i+1}ᵀ N P_{i+1}) C(i): block (I, J) of the
// coarse matrix is Σ_{a,b} C(a, I) C(b, J) block (a, b) of the fine one. That map (a
// sparse matrix from fine to coarse upper entries, built once) replaces a sparse–sparse
// triple product of 3#V-sized matrices per solve.
//
// Assembled matrix. The CG system of level i is data + κ_i · regularizer_i on the union of
// both patterns, interleaved (unknown 3v + axis), column-major; its structure is built
// once (LevelMatrix), a solve writes its values (AssembleLevelMatrix).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "geometry/loop_operators.h"
#include "solver/motion/conjugate_gradient.h"

namespace subflow::solver {

// A symmetric vertex pattern with sorted inner indices.
struct SymmetricPattern {
  Eigen::SparseMatrix<double> pattern;  // #V square, column-major, values unused
  std::vector<int> mirror;              // per entry (r, c): the index of entry (c, r)

  // Index of entry (row, column), or −1 when it is not in the pattern.
  int Entry(int row, int column) const;
  // Index of the entry holding the block sums of (row, column): the upper one of the pair.
  int UpperEntry(int row, int column) const { return Entry(std::min(row, column), std::max(row, column)); }
  int entries() const { return static_cast<int>(pattern.nonZeros()); }
};

// The pattern of `structure` (square, symmetric; values ignored), sorted, with mirrors.
SymmetricPattern MakeSymmetricPattern(const Eigen::SparseMatrix<double>& structure);

// The map from the block sums of `fine` (level i + 1) to those of level i, whose pattern
// `coarse` it also returns: Cᵀ |fine| C for the refinement C (#V(i+1) × #V(i)).
// Rows: coarse entries (lower ones empty); columns: fine entries.
geometry::SparseMatrix CoarseningMap(const SymmetricPattern& fine,
                                     const geometry::SparseMatrix& refinement,
                                     SymmetricPattern* coarse);

// Block sums of the coarse level: `map` × `fine_sums` (6 per entry), parallel over rows.
std::vector<double> CoarsenBlockSums(const geometry::SparseMatrix& map, const std::vector<double>& fine_sums);

// The structure of one level's CG matrix.
struct LevelMatrix {
  Eigen::SparseMatrix<double> regularizer;  // 3#V square: the union pattern, regularizer values
  std::vector<int> data_slot;    // per nonzero: index into the block sums, or −1
  std::vector<int> diagonal_slot;  // per unknown 3v + a: index of its diagonal data value
  // The same structure in 3×3 blocks (the CG's product; outer and row only, no values),
  // and per nonzero of `regularizer` the index of its value among the blocks' values.
  BlockSparseMatrix blocks;
  std::vector<int> block_slot;
};

LevelMatrix MakeLevelMatrix(const SymmetricPattern& data_pattern,
                            const Eigen::SparseMatrix<double>& regularizer3);

// Mean diagonal of the data part (κ_i per unknown) from the block sums.
double DataStiffness(const LevelMatrix& level, const std::vector<double>& sums);

// data + stiffness · regularizer on the level's union pattern, compressed.
Eigen::SparseMatrix<double> AssembleLevelMatrix(const LevelMatrix& level, const std::vector<double>& sums,
                                                double stiffness);
// The same values in the block form (MakeBlockSparse of AssembleLevelMatrix, without the
// scalar matrix in between).
BlockSparseMatrix AssembleLevelBlocks(const LevelMatrix& level, const std::vector<double>& sums, double stiffness);

}  // namespace subflow::solver
