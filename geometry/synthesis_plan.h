// Precomputed tables for the fused synthesis step of level i ≥ 1 (local_frames.h,
// RefineAndAddDetails): the limit tangents of the predicted points p = C(i−1) c at every
// vertex of level i, written as linear functions of the coarse points c (and of the even
// predicted points), so that the step never gathers from the (4× larger) predicted array
// and never stores its odd rows.
//
// Even vertex v (interior): level i's ring of v is the ring of odd vertices on the edges
// (v, r_j) of level i−1, rotated by s (fine ring[j] is on edge (v, r_{j+s})). Loop's odd
// rule makes the limit tangent masks eigenvectors, T(i)·C(i−1) = λ T(i−1) at v, so
//   t1 ∝ cos φ t1_c + sin φ t2_c,  t2 ∝ cos φ t2_c − sin φ t1_c,  φ = 2πs/K,
// with (t1_c, t2_c) the tangents of level i−1's stencil at v (λ > 0 does not change the
// frame, which depends on the directions only).
//
// Odd vertex m on an interior edge (a, b) with opposite vertices P (face of a → b) and Q:
// its ring (valence 6) is, counter-clockwise from A = p(a), (A, m(a,Q), m(b,Q), B, m(b,P),
// m(a,P)) for one of the two labellings (a, b) of the edge, rotated by s. With x1 … x4 the
// vertices across the edges (a,Q), (b,Q), (b,P), (a,P) (from b, a, a, b) and Loop's odd
// rule expanded, the tangents of the ring starting at A are
//   t1_0 = (A − B) + ¼ (a − b) + (1/16)((x1 + x4) − (x2 + x3))
//   t2_0 = (√3/2) (¾ (Q − P) + ⅛ ((x1 + x2) − (x3 + x4)))
// and the actual ones t1 = cos φ t1_0 − sin φ t2_0, t2 = cos φ t2_0 + sin φ t1_0, φ = 2πs/6.
//
// Any other vertex (boundary, or a neighbourhood that does not have this structure) gets a
// general row of T(i)·C(i−1): two weights per coarse column.
#pragma once

#include <cstdint>
#include <vector>

#include "geometry/mesh_topology.h"
#include "geometry/point_stencil.h"

namespace subflow::geometry {

struct SynthesisPlan {
  static constexpr std::uint8_t kGeneral = 255;  // rotation code of a general-row vertex

  int coarse_vertex_count = 0;
  int odd_vertex_count = 0;
  // Rotations (cos φ, sin φ) as above; index 0 is the identity (1, 0).
  std::vector<double> rotations;
  // Per even vertex: rotation index, or kGeneral.
  std::vector<std::uint8_t> even_rotation;
  // Per odd vertex: rotation index, or kGeneral.
  std::vector<std::uint8_t> odd_rotation;
  // Per odd vertex, 8 coarse columns (a, b, P, Q, x1, x2, x3, x4); for a kGeneral vertex
  // the first is its general row.
  std::vector<int> odd_columns;
  // Per even vertex of kGeneral: its general row (index); others −1.
  std::vector<int> even_general_row;
  // General rows of T(i)·C(i−1): entries offsets[r] … offsets[r+1]−1, coarse column
  // columns[k], weights weights[2k] (T1), weights[2k+1] (T2).
  std::vector<int> general_offsets{0};
  std::vector<int> general_columns;
  std::vector<double> general_weights;
};

// The plan of fine level i from the topologies of levels i−1 and i and the stencils of
// refinement C(i−1) and of the tangents of level i (LoopHierarchy builds one per level).
SynthesisPlan BuildSynthesisPlan(const MeshTopology& coarse, const MeshTopology& fine,
                                 const PointStencil& coarse_refinement,
                                 const PointStencil& fine_tangents);

}  // namespace subflow::geometry
