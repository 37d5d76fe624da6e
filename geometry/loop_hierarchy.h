// The connectivity of a Loop subdivision surface over levels 0..n and its sparse
// operators (method §3.1–3.2, eq. 7–10, 14–17), built once from a base triangle mesh and
// immutable afterwards. Positions are never stored here: they live in the caller's
// Positions matrices (#V(i)×3, rows = vertices) and the operators act on them.
//
// Nested vertex indices: level i+1 keeps the #V(i) vertices of level i first ("even"
// vertices, same indices), then appends one "odd" vertex per edge e of level i, in the
// edge order of Topology(i): odd vertex #V(i) + e, whose parent edge is
// (Topology(i).EdgeVertex(e, 0), Topology(i).EdgeVertex(e, 1)).
//
// Faces: face f = (a, b, c) of level i splits into the four faces 4f + k of level i+1.
// With m_ab, m_bc, m_ca the odd vertices of its edges (a,b), (b,c), (c,a):
//   4f + 0 = (a,    m_ab, m_ca)     corner child of corner 0 (a at position 0)
//   4f + 1 = (m_ab, b,    m_bc)     corner child of corner 1 (b at position 1)
//   4f + 2 = (m_ca, m_bc, c   )     corner child of corner 2 (c at position 2)
//   4f + 3 = (m_ab, m_bc, m_ca)     centre child
// All keep the parent's orientation. A point with barycentric coordinates w on child k
// (weights of the child's corners, in the order above) has parent barycentrics
//   k < 3:  u = w_k e_k + Σ_{j≠k} w_j (e_k + e_j)/2
//   k = 3:  u = w_0 (e_0 + e_1)/2 + w_1 (e_1 + e_2)/2 + w_2 (e_2 + e_0)/2
// (ChildToParentBarycentric / ParentToChildBarycentric below).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "geometry/loop_operators.h"
#include "geometry/mesh_topology.h"
#include "geometry/point_stencil.h"
#include "geometry/synthesis_plan.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

class LoopHierarchy {
 public:
  // Builds levels 0..levels from the base faces F0 over `vertex_count` vertices, and
  // every operator of every level. Throws subflow::Error naming `source` when F0 is empty
  // or not an oriented 2-manifold (see MeshTopology), when a vertex is referenced by no
  // face, when an interior vertex has fewer than 3 neighbours, when `levels` < 0, or when
  // the finest level would exceed 2^31 faces.
  LoopHierarchy(const Faces& base_faces, int vertex_count, int levels,
                const std::string& source = "base mesh",
                const TaubinParameters& taubin = TaubinParameters());

  // n: the finest level; levels are 0..n.
  int finest_level() const { return static_cast<int>(faces_.size()) - 1; }
  int VertexCount(int level) const { return topology_.at(level).vertex_count(); }
  int FaceCount(int level) const { return static_cast<int>(faces_.at(level).rows()); }
  const Faces& LevelFaces(int level) const { return faces_.at(level); }
  const MeshTopology& Topology(int level) const { return topology_.at(level); }

  // True when `vertex` of `level` ≥ 1 was inserted on an edge of level − 1.
  bool IsOddVertex(int level, int vertex) const;
  // The two level−1 endpoints of the edge on which odd `vertex` of `level` was inserted.
  std::array<int, 2> ParentEdge(int level, int vertex) const;

  static int ChildFace(int face, int k) { return 4 * face + k; }
  static Eigen::Vector3d ChildToParentBarycentric(int child_index, const Eigen::Vector3d& w);
  // The child of a face holding the point with parent barycentrics u, and its barycentrics
  // there (ties go to the corner children; u must be a convex combination).
  static int ParentToChildBarycentric(const Eigen::Vector3d& u, Eigen::Vector3d* w);

  // C(i): #V(i+1) × #V(i), level → level + 1 (0 ≤ level < n). Even rows first.
  const SparseMatrix& Refinement(int level) const { return refinement_.at(level); }
  // H(i) = (I − µL)(I − λL): #V(i) × #V(i), Taubin smoothing on level i (0 ≤ i ≤ n).
  const SparseMatrix& TaubinSmoothing(int level) const { return taubin_.at(level); }
  // The analysis operator of eq. 14/18 for 1 ≤ level ≤ n: #V(level−1) × #V(level), the
  // even rows of H(level): c(i−1) = (H(i) c(i)) restricted to the vertices level i−1
  // keeps. (Level i−1's vertices are the first #V(i−1) of level i, so smoothing on the
  // fine level and keeping the coarse vertices is the sparse, local choice.)
  const SparseMatrix& Coarsening(int level) const { return coarsening_.at(level - 1); }
  // Limit positions and tangents of level i's control points (loop_operators.h).
  const SparseMatrix& LimitPositions(int level) const { return limit_positions_.at(level); }
  // which = 0: T1 (first tangent), 1: T2 (second tangent). n = T1 c × T2 c is outward.
  const SparseMatrix& LimitTangent(int level, int which) const {
    return limit_tangents_.at(level).at(which);
  }
  // Hot-path forms (point_stencil.h): C(i) for 0 ≤ level < n, and [T1, T2] (two channels).
  const PointStencil& RefinementStencil(int level) const { return refinement_stencils_.at(level); }
  const PointStencil& LimitTangentStencil(int level) const { return tangent_stencils_.at(level); }
  // The tables of the fused synthesis step into `level` (1 ≤ level ≤ n, synthesis_plan.h).
  const SynthesisPlan& SynthesisPlanOf(int level) const { return synthesis_plans_.at(level - 1); }

  // Control points of `to_level` from control points of `from_level` by repeated
  // refinement (no details): c(to) = C(to−1) ⋯ C(from) c(from), with the stencils.
  Positions Refine(const Positions& control_points, int from_level, int to_level) const;

 private:
  std::vector<Faces> faces_;
  std::vector<MeshTopology> topology_;
  std::vector<SparseMatrix> refinement_;   // levels 0..n−1
  std::vector<SparseMatrix> taubin_;       // levels 0..n
  std::vector<SparseMatrix> coarsening_;   // levels 1..n, stored at [level − 1]
  std::vector<SparseMatrix> limit_positions_;
  std::vector<std::array<SparseMatrix, 2>> limit_tangents_;
  std::vector<PointStencil> refinement_stencils_;  // levels 0..n−1
  std::vector<PointStencil> tangent_stencils_;     // levels 0..n
  std::vector<SynthesisPlan> synthesis_plans_;     // levels 1..n, stored at [level − 1]
};

// The faces of the next level (the 1-to-4 split documented above) from level i's faces and
// topology; odd vertex numbering #V(i) + edge.
Faces SplitFaces(const Faces& faces, const MeshTopology& topology);

}  // namespace subflow::geometry
