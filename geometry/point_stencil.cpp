#include "geometry/point_stencil.h"

#include <algorithm>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::geometry {
namespace {

// Rows per parallel block, and the size below which a loop stays serial: below ~32k rows
// the work (< ~0.3 ms) does not repay scheduling threads.
constexpr int kBlockRows = 8192;
constexpr int kParallelRows = 32768;

}  // namespace

void ForEachRowBlock(int count, const std::function<void(int, int)>& body) {
  if (count < kParallelRows) {
    body(0, count);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, count, kBlockRows),
                    [&](const tbb::blocked_range<int>& range) { body(range.begin(), range.end()); });
}

void PointStencil::AddRow(const std::vector<int>& columns, const std::vector<double>& weights,
                          int pattern) {
  SUBFLOW_CHECK(weights.size() == columns.size() * static_cast<size_t>(channels_),
                "stencil row: weights do not match columns");
  const auto found = std::find(pattern_keys_.begin(), pattern_keys_.end(), pattern);
  int offset;
  if (found == pattern_keys_.end()) {
    offset = static_cast<int>(weights_.size());
    weights_.insert(weights_.end(), weights.begin(), weights.end());
    pattern_keys_.push_back(pattern);
    pattern_offsets_.push_back(offset);
  } else {
    offset = pattern_offsets_[found - pattern_keys_.begin()];
    SUBFLOW_CHECK(offset + weights.size() <= weights_.size() &&
                      std::equal(weights.begin(), weights.end(), weights_.begin() + offset),
                  "stencil rows with one pattern key must share their weights");
  }
  for (int column : columns) SUBFLOW_CHECK(column >= 0 && column < cols_, "stencil column out of range");
  columns_.insert(columns_.end(), columns.begin(), columns.end());
  offsets_.push_back(static_cast<int>(columns_.size()));
  weight_offsets_.push_back(offset);
}

int PointStencil::PatternWeightOffset(int pattern) const {
  const auto found = std::find(pattern_keys_.begin(), pattern_keys_.end(), pattern);
  return found == pattern_keys_.end() ? -1 : pattern_offsets_[found - pattern_keys_.begin()];
}

void PointStencil::Apply(const Positions& x, Positions* y) const {
  SUBFLOW_CHECK(channels_ == 1, "Apply needs a one-channel stencil");
  SUBFLOW_CHECK(x.rows() == cols_, "stencil and points do not match");
  SUBFLOW_CHECK(y != &x, "output aliases input");
  y->resize(rows(), 3);
  const double* in = x.data();
  double* out = y->data();
  // Rows of 4 and 7 entries (interior odd and regular even vertices of Loop's refinement,
  // almost every row) get fixed-length loops the compiler unrolls; the sums are the
  // general loop's, in its order.
  const auto apply_rows = [&](auto entries, int begin, int end) {
    for (int row = begin; row < end; ++row) {
      const double* w = weights_.data() + weight_offsets_[row];
      const int* column = columns_.data() + offsets_[row];
      const int count = decltype(entries)::value > 0 ? decltype(entries)::value
                                                     : offsets_[row + 1] - offsets_[row];
      double sx = 0.0, sy = 0.0, sz = 0.0;
      for (int i = 0; i < count; ++i) {
        const double* p = in + 3 * static_cast<Eigen::Index>(column[i]);
        sx += w[i] * p[0];
        sy += w[i] * p[1];
        sz += w[i] * p[2];
      }
      out[3 * row] = sx;
      out[3 * row + 1] = sy;
      out[3 * row + 2] = sz;
    }
  };
  ForEachRowBlock(rows(), [&](int begin, int end) {
    int row = begin;
    while (row < end) {
      // A run of rows with the same length.
      const int length = offsets_[row + 1] - offsets_[row];
      int run_end = row + 1;
      while (run_end < end && offsets_[run_end + 1] - offsets_[run_end] == length) ++run_end;
      if (length == 4)
        apply_rows(std::integral_constant<int, 4>(), row, run_end);
      else if (length == 7)
        apply_rows(std::integral_constant<int, 7>(), row, run_end);
      else
        apply_rows(std::integral_constant<int, 0>(), row, run_end);
      row = run_end;
    }
  });
}

}  // namespace subflow::geometry
