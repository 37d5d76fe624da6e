// A B for a row-major sparse A (a per-vertex operator: limit evaluation, Loop refinement)
// and a row-major dense B with a fixed number of columns (x, y, z; or more), parallel over
// A's rows (TBB). Each row sums its entries in A's order — the same sums as Eigen's
// product and as a serial loop — so the result does not depend on the threads.
#pragma once

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

}  // namespace subflow::solver
