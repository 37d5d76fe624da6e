#include "geometry/loop_operators.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "geometry/loop_weights.h"
#include "geometry/point_stencil.h"

namespace subflow::geometry {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Builds a row-major matrix row by row straight into compressed storage (much faster
// than triplets for the millions of entries of a fine level). Each row's entries are
// sorted by column and duplicate columns summed when the row ends.
class RowBuilder {
 public:
  RowBuilder(int rows, int cols, size_t expected_nonzeros) : rows_(rows), cols_(cols) {
    offsets_.reserve(static_cast<size_t>(rows) + 1);
    offsets_.push_back(0);
    columns_.reserve(expected_nonzeros);
    values_.reserve(expected_nonzeros);
  }
  void Add(int column, double value) {
    columns_.push_back(column);
    values_.push_back(value);
  }
  void EndRow() {
    const size_t begin = static_cast<size_t>(offsets_.back());
    // Insertion sort: rows hold a handful of entries.
    for (size_t i = begin + 1; i < columns_.size(); ++i) {
      const int column = columns_[i];
      const double value = values_[i];
      size_t j = i;
      for (; j > begin && columns_[j - 1] > column; --j) {
        columns_[j] = columns_[j - 1];
        values_[j] = values_[j - 1];
      }
      columns_[j] = column;
      values_[j] = value;
    }
    size_t end = begin;
    for (size_t i = begin; i < columns_.size(); ++i) {
      if (end > begin && columns_[end - 1] == columns_[i]) {
        values_[end - 1] += values_[i];
      } else {
        columns_[end] = columns_[i];
        values_[end] = values_[i];
        ++end;
      }
    }
    columns_.resize(end);
    values_.resize(end);
    offsets_.push_back(static_cast<int>(end));
  }
  SparseMatrix Build() {
    SUBFLOW_CHECK(static_cast<int>(offsets_.size()) == rows_ + 1, "rows not all ended");
    SparseMatrix matrix(rows_, cols_);
    matrix.resizeNonZeros(static_cast<Eigen::Index>(values_.size()));
    std::copy(offsets_.begin(), offsets_.end(), matrix.outerIndexPtr());
    std::copy(columns_.begin(), columns_.end(), matrix.innerIndexPtr());
    std::copy(values_.begin(), values_.end(), matrix.valuePtr());
    return matrix;
  }

 private:
  int rows_, cols_;
  std::vector<int> offsets_;
  std::vector<int> columns_;
  std::vector<double> values_;
};

// Every operator needs a 1-ring at every vertex.
void CheckReferenced(const MeshTopology& topology, int v) {
  if (topology.Valence(v) == 0)
    ThrowError("Loop operators", "vertex " + std::to_string(v),
               "referenced by no face (remove unreferenced vertices first)");
}

}  // namespace

void MultiplyPoints(const SparseMatrix& matrix, const Positions& x, Positions* y) {
  SUBFLOW_CHECK(matrix.cols() == x.rows(), "operator and points do not match");
  SUBFLOW_CHECK(matrix.isCompressed(), "operator must be compressed");
  SUBFLOW_CHECK(y != &x, "output aliases input");
  y->resize(matrix.rows(), 3);
  const int* offsets = matrix.outerIndexPtr();
  const int* columns = matrix.innerIndexPtr();
  const double* values = matrix.valuePtr();
  const double* in = x.data();
  double* out = y->data();
  ForEachRowBlock(static_cast<int>(matrix.rows()), [&](int begin, int end) {
    for (int row = begin; row < end; ++row) {
      double sx = 0.0, sy = 0.0, sz = 0.0;
      for (int i = offsets[row]; i < offsets[row + 1]; ++i) {
        const double w = values[i];
        const double* p = in + 3 * static_cast<Eigen::Index>(columns[i]);
        sx += w * p[0];
        sy += w * p[1];
        sz += w * p[2];
      }
      out[3 * row] = sx;
      out[3 * row + 1] = sy;
      out[3 * row + 2] = sz;
    }
  });
}

Positions MultiplyPoints(const SparseMatrix& matrix, const Positions& x) {
  Positions y;
  MultiplyPoints(matrix, x, &y);
  return y;
}

namespace {

// Pattern keys of the stencils: rows with equal keys have equal weights.
constexpr int kInteriorEvenPattern = 0;     // + valence
constexpr int kBoundaryEvenPattern = -1;
constexpr int kInteriorOddPattern = -2;
constexpr int kBoundaryOddPattern = -3;
constexpr int kBoundaryTangentPattern = 1000;  // + faces around the boundary vertex

// The rows of C (loop_operators.h), each as sink.Add(column, weight)… sink.EndRow(pattern).
template <typename Sink>
void EmitRefinementRows(const MeshTopology& topology, Sink& sink) {
  const int n = topology.vertex_count();
  for (int v = 0; v < n; ++v) {
    CheckReferenced(topology, v);
    const IndexRange ring = topology.Ring(v);
    if (topology.IsBoundaryVertex(v)) {
      sink.Add(v, kLoopBoundaryEvenCenterWeight);
      sink.Add(ring.front(), kLoopBoundaryEvenNeighbourWeight);
      sink.Add(ring.back(), kLoopBoundaryEvenNeighbourWeight);
      sink.EndRow(kBoundaryEvenPattern);
    } else {
      const int valence = ring.size();
      const double alpha = LoopAlpha(valence);
      sink.Add(v, 1.0 - alpha);
      for (int r : ring) sink.Add(r, alpha / valence);
      sink.EndRow(kInteriorEvenPattern + valence);
    }
  }
  for (int e = 0; e < topology.edge_count(); ++e) {
    const int a = topology.EdgeVertex(e, 0), b = topology.EdgeVertex(e, 1);
    if (topology.IsBoundaryEdge(e)) {
      sink.Add(a, kLoopBoundaryOddWeight);
      sink.Add(b, kLoopBoundaryOddWeight);
      sink.EndRow(kBoundaryOddPattern);
    } else {
      const int h = topology.EdgeHalfedge(e);
      sink.Add(a, kLoopOddEdgeWeight);
      sink.Add(b, kLoopOddEdgeWeight);
      sink.Add(topology.HalfedgeOpposite(h), kLoopOddOppositeWeight);
      sink.Add(topology.HalfedgeOpposite(topology.HalfedgeTwin(h)), kLoopOddOppositeWeight);
      sink.EndRow(kInteriorOddPattern);
    }
  }
}

// The rows of [T1, T2] in ring order, each as sink.Add(column, w1, w2)… sink.EndRow(pattern).
template <typename Sink>
void EmitTangentRows(const MeshTopology& topology, Sink& sink) {
  for (int v = 0; v < topology.vertex_count(); ++v) {
    CheckReferenced(topology, v);
    const IndexRange ring = topology.Ring(v);
    const int valence = ring.size();
    if (!topology.IsBoundaryVertex(v)) {
      for (int j = 0; j < valence; ++j) {
        const double angle = 2.0 * kPi * j / valence;
        sink.Add(ring[j], std::cos(angle), std::sin(angle));
      }
      sink.EndRow(valence);
      continue;
    }
    const int k = valence - 1;  // faces around the boundary vertex
    std::vector<double> across(valence + 1, 0.0);  // [v, r_0 … r_k]
    if (k == 1) {
      across = {-2.0, 1.0, 1.0};
    } else if (k == 2) {  // the general formula gives a = 0, b = −1 up to rounding
      across = {-1.0, 0.0, 1.0, 0.0};
    } else {
      const double theta = kPi / k;
      const double c = std::cos(theta), s = std::sin(theta);
      const double a = -c * (1.0 + c) / (s * (1.0 + 2.0 * c));
      across[0] = -2.0 * a - (1.0 + c) / s;  // b; cot(θ/2) = (1 + cos θ)/sin θ
      across[1] = across[k + 1] = a;
      for (int j = 1; j < k; ++j) across[j + 1] = std::sin(j * theta);
    }
    sink.Add(v, 0.0, across[0]);
    for (int j = 0; j <= k; ++j)
      sink.Add(ring[j], j == 0 ? 1.0 : j == k ? -1.0 : 0.0, across[j + 1]);
    sink.EndRow(kBoundaryTangentPattern + k);
  }
}

// Sinks: rows of a SparseMatrix (zero weights dropped), or of a PointStencil.
struct MatrixSink {
  RowBuilder rows;
  void Add(int column, double weight) {
    if (weight != 0.0) rows.Add(column, weight);
  }
  void EndRow(int) { rows.EndRow(); }
};

struct TangentMatrixSink {
  MatrixSink first, second;
  void Add(int column, double w1, double w2) {
    first.Add(column, w1);
    second.Add(column, w2);
  }
  void EndRow(int pattern) {
    first.EndRow(pattern);
    second.EndRow(pattern);
  }
};

struct StencilSink {
  PointStencil stencil;
  std::vector<int> columns;
  std::vector<double> weights;
  void Add(int column, double weight) {
    columns.push_back(column);
    weights.push_back(weight);
  }
  void Add(int column, double w1, double w2) {
    columns.push_back(column);
    weights.push_back(w1);
    weights.push_back(w2);
  }
  void EndRow(int pattern) {
    stencil.AddRow(columns, weights, pattern);
    columns.clear();
    weights.clear();
  }
};

}  // namespace

SparseMatrix LoopRefinementMatrix(const MeshTopology& topology) {
  const int n = topology.vertex_count();
  const int m = topology.edge_count();
  MatrixSink sink{RowBuilder(n + m, n, static_cast<size_t>(n) * 7 + static_cast<size_t>(m) * 4)};
  EmitRefinementRows(topology, sink);
  return sink.rows.Build();
}

PointStencil LoopRefinementStencil(const MeshTopology& topology) {
  StencilSink sink{PointStencil(1, topology.vertex_count()), {}, {}};
  EmitRefinementRows(topology, sink);
  return std::move(sink.stencil);
}

SparseMatrix UmbrellaLaplacian(const MeshTopology& topology) {
  const int n = topology.vertex_count();
  RowBuilder rows(n, n, static_cast<size_t>(n) * 7);
  for (int v = 0; v < n; ++v) {
    CheckReferenced(topology, v);
    const IndexRange ring = topology.Ring(v);
    rows.Add(v, 1.0);
    if (topology.IsBoundaryVertex(v)) {
      rows.Add(ring.front(), -0.5);
      rows.Add(ring.back(), -0.5);
    } else {
      for (int r : ring) rows.Add(r, -1.0 / ring.size());
    }
    rows.EndRow();
  }
  return rows.Build();
}

SparseMatrix TaubinSmoothingMatrix(const MeshTopology& topology,
                                   const TaubinParameters& parameters) {
  // H = I − (λ + µ) L + λµ L², row by row (Gustavson's sparse product with a dense
  // accumulator): row v of L² gathers the rows of L at v's neighbours.
  const SparseMatrix laplacian = UmbrellaLaplacian(topology);
  const int n = topology.vertex_count();
  const double linear = -(parameters.lambda + parameters.mu);
  const double quadratic = parameters.lambda * parameters.mu;
  const int* offsets = laplacian.outerIndexPtr();
  const int* columns = laplacian.innerIndexPtr();
  const double* values = laplacian.valuePtr();
  RowBuilder rows(n, n, static_cast<size_t>(n) * 19);
  std::vector<double> accumulator(n, 0.0);
  std::vector<int> touched;
  std::vector<char> is_touched(n, 0);
  auto add = [&](int column, double value) {
    if (!is_touched[column]) {
      is_touched[column] = 1;
      touched.push_back(column);
    }
    accumulator[column] += value;
  };
  for (int v = 0; v < n; ++v) {
    add(v, 1.0);
    for (int i = offsets[v]; i < offsets[v + 1]; ++i) {
      add(columns[i], linear * values[i]);
      for (int j = offsets[columns[i]]; j < offsets[columns[i] + 1]; ++j)
        add(columns[j], quadratic * values[i] * values[j]);
    }
    for (int column : touched) {
      rows.Add(column, accumulator[column]);
      accumulator[column] = 0.0;
      is_touched[column] = 0;
    }
    touched.clear();
    rows.EndRow();
  }
  return rows.Build();
}

SparseMatrix LoopLimitPositionMatrix(const MeshTopology& topology) {
  const int n = topology.vertex_count();
  RowBuilder rows(n, n, static_cast<size_t>(n) * 7);
  for (int v = 0; v < n; ++v) {
    CheckReferenced(topology, v);
    const IndexRange ring = topology.Ring(v);
    if (topology.IsBoundaryVertex(v)) {
      rows.Add(v, kLoopBoundaryLimitCenterWeight);
      rows.Add(ring.front(), kLoopBoundaryLimitNeighbourWeight);
      rows.Add(ring.back(), kLoopBoundaryLimitNeighbourWeight);
    } else {
      const int valence = ring.size();
      const LoopLimitWeights weights = LoopInteriorLimitWeights(valence);
      rows.Add(v, weights.center);
      for (int r : ring) rows.Add(r, weights.ring);
    }
    rows.EndRow();
  }
  return rows.Build();
}

std::array<SparseMatrix, 2> LoopLimitTangentMatrices(const MeshTopology& topology) {
  const int n = topology.vertex_count();
  TangentMatrixSink sink{{RowBuilder(n, n, static_cast<size_t>(n) * 6)},
                         {RowBuilder(n, n, static_cast<size_t>(n) * 6)}};
  EmitTangentRows(topology, sink);
  return {sink.first.rows.Build(), sink.second.rows.Build()};
}

PointStencil LoopLimitTangentStencil(const MeshTopology& topology) {
  StencilSink sink{PointStencil(2, topology.vertex_count()), {}, {}};
  EmitTangentRows(topology, sink);
  return std::move(sink.stencil);
}

}  // namespace subflow::geometry
