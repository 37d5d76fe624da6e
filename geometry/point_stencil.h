// The hot-path form of Loop's operators. Every row of a Loop mask has one of a few
// weight patterns (they depend only on the valence and on boundary/interior), so a
// PointStencil stores per row only its columns and an offset into a small shared table of
// weights: 4 bytes per non-zero instead of CSR's 12, and the table stays in L1 cache.
// LoopHierarchy builds one per refinement and one per tangent pair; the SparseMatrix forms
// remain the reference (and what Jacobians are built from).
//
// A stencil has 1 or 2 channels: with 2, each entry carries two weights and one pass
// yields two results per row (the tangents T1 c and T2 c of a vertex).
#pragma once

#include <functional>
#include <vector>

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

class PointStencil {
 public:
  explicit PointStencil(int channels = 1, int cols = 0) : channels_(channels), cols_(cols) {}

  // Appends a row with entries (columns[j], weights[channels·j + c]). Rows with the same
  // `pattern` key must have identical weights (checked); their weights are stored once.
  void AddRow(const std::vector<int>& columns, const std::vector<double>& weights, int pattern);

  int rows() const { return static_cast<int>(offsets_.size()) - 1; }
  int cols() const { return cols_; }
  int channels() const { return channels_; }

  // y = M x for a 1-channel stencil (x #cols×3, y #rows×3, no aliasing). Large operators
  // run in parallel over blocks of rows (TBB).
  void Apply(const Positions& x, Positions* y) const;

  // Raw access for fused loops: row r has entries offsets()[r] .. offsets()[r + 1] − 1,
  // columns()[i], and its weights start at weights() + weight_offsets()[r] (channels
  // per entry, consecutive).
  const int* offsets() const { return offsets_.data(); }
  const int* columns() const { return columns_.data(); }
  const int* weight_offsets() const { return weight_offsets_.data(); }
  const double* weights() const { return weights_.data(); }
  // The weight offset shared by the rows added with `pattern`, or −1 if there are none
  // (lets a fused loop recognise, e.g., regular vertices and use a specialised formula).
  int PatternWeightOffset(int pattern) const;

 private:
  int channels_;
  int cols_;
  std::vector<int> offsets_{0};
  std::vector<int> columns_;
  std::vector<int> weight_offsets_;
  std::vector<double> weights_;
  std::vector<int> pattern_keys_, pattern_offsets_;  // key → offset (few patterns)
};

// Calls body(begin, end) over [0, count), in parallel blocks when count is large enough
// for threads to pay off (the hot loops of synthesis), serially otherwise.
void ForEachRowBlock(int count, const std::function<void(int, int)>& body);

}  // namespace subflow::geometry
