#include "geometry/loop_operators.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "geometry/error.h"

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
  const Eigen::Index rows = matrix.rows();
  for (Eigen::Index row = 0; row < rows; ++row) {
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
}

Positions MultiplyPoints(const SparseMatrix& matrix, const Positions& x) {
  Positions y;
  MultiplyPoints(matrix, x, &y);
  return y;
}

SparseMatrix InterleaveRows(const SparseMatrix& first, const SparseMatrix& second) {
  SUBFLOW_CHECK(first.rows() == second.rows() && first.cols() == second.cols(),
                "interleaved matrices differ in shape");
  const int n = static_cast<int>(first.rows());
  RowBuilder rows(2 * n, static_cast<int>(first.cols()),
                  static_cast<size_t>(first.nonZeros() + second.nonZeros()));
  for (int v = 0; v < n; ++v) {
    for (const SparseMatrix* matrix : {&first, &second}) {
      for (SparseMatrix::InnerIterator it(*matrix, v); it; ++it) rows.Add(it.col(), it.value());
      rows.EndRow();
    }
  }
  return rows.Build();
}

double LoopAlpha(int valence) {
  const double c = 3.0 + 2.0 * std::cos(2.0 * kPi / valence);
  return 5.0 / 8.0 - c * c / 64.0;
}

SparseMatrix LoopRefinementMatrix(const MeshTopology& topology) {
  const int n = topology.vertex_count();
  const int m = topology.edge_count();
  RowBuilder rows(n + m, n, static_cast<size_t>(n) * 7 + static_cast<size_t>(m) * 4);
  for (int v = 0; v < n; ++v) {
    CheckReferenced(topology, v);
    const IndexRange ring = topology.Ring(v);
    if (topology.IsBoundaryVertex(v)) {
      rows.Add(v, 0.75);
      rows.Add(ring.front(), 0.125);
      rows.Add(ring.back(), 0.125);
    } else {
      const int valence = ring.size();
      const double alpha = LoopAlpha(valence);
      rows.Add(v, 1.0 - alpha);
      for (int r : ring) rows.Add(r, alpha / valence);
    }
    rows.EndRow();
  }
  for (int e = 0; e < m; ++e) {
    const int a = topology.EdgeVertex(e, 0), b = topology.EdgeVertex(e, 1);
    if (topology.IsBoundaryEdge(e)) {
      rows.Add(a, 0.5);
      rows.Add(b, 0.5);
    } else {
      const int h = topology.EdgeHalfedge(e);
      rows.Add(a, 0.375);
      rows.Add(b, 0.375);
      rows.Add(topology.HalfedgeOpposite(h), 0.125);
      rows.Add(topology.HalfedgeOpposite(topology.HalfedgeTwin(h)), 0.125);
    }
    rows.EndRow();
  }
  return rows.Build();
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
      rows.Add(v, 2.0 / 3.0);
      rows.Add(ring.front(), 1.0 / 6.0);
      rows.Add(ring.back(), 1.0 / 6.0);
    } else {
      const int valence = ring.size();
      const double beta = LoopAlpha(valence) / valence;
      const double omega = 3.0 / (8.0 * beta);
      rows.Add(v, omega / (omega + valence));
      for (int r : ring) rows.Add(r, 1.0 / (omega + valence));
    }
    rows.EndRow();
  }
  return rows.Build();
}

std::array<SparseMatrix, 2> LoopLimitTangentMatrices(const MeshTopology& topology) {
  const int n = topology.vertex_count();
  RowBuilder first(n, n, static_cast<size_t>(n) * 6), second(n, n, static_cast<size_t>(n) * 6);
  for (int v = 0; v < n; ++v) {
    CheckReferenced(topology, v);
    const IndexRange ring = topology.Ring(v);
    const int valence = ring.size();
    if (!topology.IsBoundaryVertex(v)) {
      for (int j = 0; j < valence; ++j) {
        const double angle = 2.0 * kPi * j / valence;
        first.Add(ring[j], std::cos(angle));
        second.Add(ring[j], std::sin(angle));
      }
    } else {
      const int k = valence - 1;  // faces around the boundary vertex
      first.Add(ring.front(), 1.0);
      first.Add(ring.back(), -1.0);
      if (k == 1) {
        second.Add(ring[0], 1.0);
        second.Add(ring[1], 1.0);
        second.Add(v, -2.0);
      } else if (k == 2) {  // the general formula gives a = 0, b = −1 up to rounding
        second.Add(ring[1], 1.0);
        second.Add(v, -1.0);
      } else {
        const double theta = kPi / k;
        const double c = std::cos(theta), s = std::sin(theta);
        const double a = -c * (1.0 + c) / (s * (1.0 + 2.0 * c));
        const double b = -2.0 * a - (1.0 + c) / s;  // cot(θ/2) = (1 + cos θ)/sin θ
        second.Add(v, b);
        second.Add(ring.front(), a);
        second.Add(ring.back(), a);
        for (int j = 1; j < k; ++j) second.Add(ring[j], std::sin(j * theta));
      }
    }
    first.EndRow();
    second.EndRow();
  }
  return {first.Build(), second.Build()};
}

}  // namespace subflow::geometry
