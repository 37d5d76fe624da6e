#include "geometry/synthesis_plan.h"

#include <cmath>
#include <utility>

#include "core/error.h"

namespace subflow::geometry {
namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

// Index of (c, s) in the plan's rotation table (added if new), or kGeneral when full.
std::uint8_t RotationIndex(SynthesisPlan* plan, double c, double s) {
  const int count = static_cast<int>(plan->rotations.size() / 2);
  for (int i = 0; i < count; ++i)
    if (plan->rotations[2 * i] == c && plan->rotations[2 * i + 1] == s)
      return static_cast<std::uint8_t>(i);
  if (count >= SynthesisPlan::kGeneral) return SynthesisPlan::kGeneral;
  plan->rotations.push_back(c);
  plan->rotations.push_back(s);
  return static_cast<std::uint8_t>(count);
}

// Appends the general row of fine vertex u: Σ_j T(u, f_j) · C(f_j, ·) over the entries of
// the fine tangent row, columns in order of first appearance. Returns its index.
int AddGeneralRow(SynthesisPlan* plan, const PointStencil& coarse_refinement,
                  const PointStencil& fine_tangents, int u) {
  std::vector<int>& columns = plan->general_columns;
  std::vector<double>& weights = plan->general_weights;
  const int first = static_cast<int>(columns.size());
  const double* tangent_weights = fine_tangents.weights() + fine_tangents.weight_offsets()[u];
  for (int i = fine_tangents.offsets()[u]; i < fine_tangents.offsets()[u + 1];
       ++i, tangent_weights += 2) {
    const int f = fine_tangents.columns()[i];
    const double* refinement_weights =
        coarse_refinement.weights() + coarse_refinement.weight_offsets()[f];
    for (int k = coarse_refinement.offsets()[f]; k < coarse_refinement.offsets()[f + 1];
         ++k, ++refinement_weights) {
      const int column = coarse_refinement.columns()[k];
      int at = first;
      while (at < static_cast<int>(columns.size()) && columns[at] != column) ++at;
      if (at == static_cast<int>(columns.size())) {
        columns.push_back(column);
        weights.push_back(0.0);
        weights.push_back(0.0);
      }
      weights[2 * at] += tangent_weights[0] * *refinement_weights;
      weights[2 * at + 1] += tangent_weights[1] * *refinement_weights;
    }
  }
  plan->general_offsets.push_back(static_cast<int>(columns.size()));
  return static_cast<int>(plan->general_offsets.size()) - 2;
}

}  // namespace

SynthesisPlan BuildSynthesisPlan(const MeshTopology& coarse, const MeshTopology& fine,
                                 const PointStencil& coarse_refinement,
                                 const PointStencil& fine_tangents) {
  const int nc = coarse.vertex_count();
  const int edges = coarse.edge_count();
  SUBFLOW_CHECK(fine.vertex_count() == nc + edges && coarse_refinement.rows() == nc + edges &&
                    fine_tangents.rows() == nc + edges,
                "synthesis plan: levels do not match");
  SynthesisPlan plan;
  plan.coarse_vertex_count = nc;
  plan.odd_vertex_count = edges;
  plan.rotations = {1.0, 0.0};
  plan.even_rotation.assign(nc, SynthesisPlan::kGeneral);
  plan.even_general_row.assign(nc, -1);
  plan.odd_rotation.assign(edges, SynthesisPlan::kGeneral);
  plan.odd_columns.assign(8 * static_cast<size_t>(edges), 0);

  // The coarse endpoints of the edge of fine odd vertex u; false for an even vertex.
  const auto edge_of = [&](int u, int* p, int* q) {
    if (u < nc) return false;
    *p = coarse.EdgeVertex(u - nc, 0);
    *q = coarse.EdgeVertex(u - nc, 1);
    return true;
  };
  const auto is_edge = [&](int u, int p, int q) {
    int x, y;
    return edge_of(u, &x, &y) && ((x == p && y == q) || (x == q && y == p));
  };

  for (int v = 0; v < nc; ++v) {
    bool fast = !coarse.IsBoundaryVertex(v) && !fine.IsBoundaryVertex(v);
    const IndexRange ring_c = coarse.Ring(v), ring_f = fine.Ring(v);
    const int valence = ring_c.size();
    int shift = -1;
    if (fast && valence >= 3 && ring_f.size() == valence) {
      int x, y;
      if (edge_of(ring_f[0], &x, &y)) {
        const int other = x == v ? y : y == v ? x : -1;
        for (int j = 0; j < valence; ++j)
          if (ring_c[j] == other) shift = j;
      }
      for (int j = 0; shift >= 0 && j < valence; ++j)
        if (!is_edge(ring_f[j], v, ring_c[(j + shift) % valence])) shift = -1;
    }
    if (shift >= 0) {
      const double angle = kTwoPi * shift / valence;
      plan.even_rotation[v] =
          shift == 0 ? 0 : RotationIndex(&plan, std::cos(angle), -std::sin(angle));
    }
    if (plan.even_rotation[v] == SynthesisPlan::kGeneral)
      plan.even_general_row[v] = AddGeneralRow(&plan, coarse_refinement, fine_tangents, v);
  }

  const int* offsets = coarse_refinement.offsets();
  const int* columns = coarse_refinement.columns();
  // The vertex across the edge of odd vertex u from `near` (interior edges), or −1.
  const auto across = [&](int u, int near) {
    if (offsets[u + 1] - offsets[u] != 4) return -1;
    const int o1 = columns[offsets[u] + 2], o2 = columns[offsets[u] + 3];
    return o1 == near ? o2 : o2 == near ? o1 : -1;
  };
  for (int e = 0; e < edges; ++e) {
    const int m = nc + e;
    const IndexRange ring = fine.Ring(m);
    bool found = false;
    if (!coarse.IsBoundaryEdge(e) && !fine.IsBoundaryVertex(m) && ring.size() == 6 &&
        offsets[m + 1] - offsets[m] == 4) {
      const int* row = columns + offsets[m];
      const int p = row[2], q = row[3];
      for (int flip = 0; flip < 2 && !found; ++flip) {
        const int a = flip ? row[1] : row[0], b = flip ? row[0] : row[1];
        int shift = -1;
        for (int j = 0; j < 6; ++j)
          if (ring[j] == a) shift = j;
        if (shift < 0) continue;
        const auto at = [&](int k) { return ring[(shift + k) % 6]; };
        if (at(3) != b || !is_edge(at(1), a, q) || !is_edge(at(2), b, q) ||
            !is_edge(at(4), b, p) || !is_edge(at(5), a, p))
          continue;
        const int x1 = across(at(1), b), x2 = across(at(2), a), x3 = across(at(4), a),
                  x4 = across(at(5), b);
        if (x1 < 0 || x2 < 0 || x3 < 0 || x4 < 0) continue;
        const double angle = kTwoPi * shift / 6;
        const std::uint8_t rotation =
            shift == 0 ? 0 : RotationIndex(&plan, std::cos(angle), std::sin(angle));
        if (rotation == SynthesisPlan::kGeneral) continue;
        int* out = plan.odd_columns.data() + 8 * static_cast<size_t>(e);
        out[0] = a, out[1] = b, out[2] = p, out[3] = q;
        out[4] = x1, out[5] = x2, out[6] = x3, out[7] = x4;
        plan.odd_rotation[e] = rotation;
        found = true;
      }
    }
    if (!found)
      plan.odd_columns[8 * static_cast<size_t>(e)] =
          AddGeneralRow(&plan, coarse_refinement, fine_tangents, m);
  }
  return plan;
}

}  // namespace subflow::geometry
