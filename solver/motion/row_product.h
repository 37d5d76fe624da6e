// A B for a row-major sparse A (a per-vertex operator: limit evaluation, Loop refinement)
// and a row-major dense B with a fixed number of columns (x, y, z; or more), parallel over
// A's rows (TBB). Each row sums its entries in A's order — the same sums as Eigen's
// product and as a serial loop — so the result does not depend on the threads.
// Aᵀ B likewise without forming Aᵀ (TransposeParallelProduct): A's rows are cut into chunks
// whose bounds depend on A's size alone; each chunk scatters its rows into its own sums,
// and the chunks' sums are added in chunk order, so that result does not depend on the
// threads either.
#pragma once

#include <algorithm>
#include <vector>

#include <Eigen/Core>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/loop_operators.h"  // geometry::SparseMatrix

namespace subflow::solver {

template <int Columns>
using RowMajorColumns = Eigen::Matrix<double, Eigen::Dynamic, Columns, Eigen::RowMajor>;

template <int Columns>
RowMajorColumns<Columns> RowParallelProduct(const geometry::SparseMatrix& A,
                                            const Eigen::Ref<const RowMajorColumns<Columns>>& B) {
  SUBFLOW_CHECK(A.cols() == B.rows(), "product of mismatched sizes");
  SUBFLOW_CHECK(A.isCompressed(), "product of an uncompressed matrix");
  RowMajorColumns<Columns> result(A.rows(), Columns);
  tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(A.rows()), 2048),
                    [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r < range.end(); ++r) {
      double sum[Columns] = {};
      for (int k = A.outerIndexPtr()[r]; k < A.outerIndexPtr()[r + 1]; ++k) {
        const double w = A.valuePtr()[k];
        const double* b = B.row(A.innerIndexPtr()[k]).data();
        for (int i = 0; i < Columns; ++i) sum[i] += w * b[i];
      }
      for (int i = 0; i < Columns; ++i) result(r, i) = sum[i];
    }
  });
  return result;
}

// Aᵀ B for a row-major sparse A (#R × #C) and B (#R × Columns): #C × Columns. For a tall A
// (samples × control points) it needs no copy of Aᵀ, which would be as large as A.
template <int Columns>
RowMajorColumns<Columns> TransposeParallelProduct(const geometry::SparseMatrix& A,
                                                  const Eigen::Ref<const RowMajorColumns<Columns>>& B) {
  SUBFLOW_CHECK(A.rows() == B.rows(), "product of mismatched sizes");
  SUBFLOW_CHECK(A.isCompressed(), "product of an uncompressed matrix");
  constexpr int kRowsPerChunk = 32768, kMaxChunks = 16;
  const int rows = static_cast<int>(A.rows());
  const int chunks = std::clamp(rows / kRowsPerChunk, 1, kMaxChunks);
  std::vector<RowMajorColumns<Columns>> partial(chunks);
  tbb::parallel_for(0, chunks, [&](int chunk) {
    RowMajorColumns<Columns>& sum = partial[chunk];
    sum = RowMajorColumns<Columns>::Zero(A.cols(), Columns);
    const int first = static_cast<int>(static_cast<long>(rows) * chunk / chunks);
    const int last = static_cast<int>(static_cast<long>(rows) * (chunk + 1) / chunks);
    for (int r = first; r < last; ++r) {
      const double* b = B.row(r).data();
      for (int k = A.outerIndexPtr()[r]; k < A.outerIndexPtr()[r + 1]; ++k) {
        const double w = A.valuePtr()[k];
        double* out = sum.row(A.innerIndexPtr()[k]).data();
        for (int i = 0; i < Columns; ++i) out[i] += w * b[i];
      }
    }
  });
  RowMajorColumns<Columns> result = std::move(partial[0]);
  for (int chunk = 1; chunk < chunks; ++chunk) result += partial[chunk];
  return result;
}

}  // namespace subflow::solver
