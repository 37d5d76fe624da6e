#include "geometry/loop_hierarchy.h"

#include <limits>
#include <string>

#include "core/error.h"

namespace subflow::geometry {

Faces SplitFaces(const Faces& faces, const MeshTopology& topology) {
  const int face_count = static_cast<int>(faces.rows());
  const int vertex_count = topology.vertex_count();
  Faces children(4 * static_cast<Eigen::Index>(face_count), 3);
  for (int f = 0; f < face_count; ++f) {
    const int a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
    // FaceEdge(f, k) is the edge of half-edge 3f + k, from corner k to corner k + 1.
    const int m_ab = vertex_count + topology.FaceEdge(f, 0);
    const int m_bc = vertex_count + topology.FaceEdge(f, 1);
    const int m_ca = vertex_count + topology.FaceEdge(f, 2);
    children.row(4 * f + 0) << a, m_ab, m_ca;
    children.row(4 * f + 1) << m_ab, b, m_bc;
    children.row(4 * f + 2) << m_ca, m_bc, c;
    children.row(4 * f + 3) << m_ab, m_bc, m_ca;
  }
  return children;
}

LoopHierarchy::LoopHierarchy(const Faces& base_faces, int vertex_count, int levels,
                             const std::string& source, const TaubinParameters& taubin) {
  if (levels < 0)
    ThrowError(source, "levels", "expected a level count ≥ 0, got " + std::to_string(levels));
  if (base_faces.rows() == 0) ThrowError(source, "faces", "expected at least one triangle");
  {
    // 4^levels × #F0 faces must fit an int.
    double finest_faces = static_cast<double>(base_faces.rows());
    for (int i = 0; i < levels; ++i) finest_faces *= 4.0;
    if (finest_faces > std::numeric_limits<int>::max())
      ThrowError(source, "levels",
                 std::to_string(levels) + " levels of " + std::to_string(base_faces.rows()) +
                     " faces exceed 2^31 faces at the finest level");
  }

  faces_.push_back(base_faces);
  topology_.emplace_back(base_faces, vertex_count, source);
  const MeshTopology& base = topology_.front();
  for (int v = 0; v < vertex_count; ++v) {
    if (base.Valence(v) == 0)
      ThrowError(source, "vertex " + std::to_string(v),
                 "referenced by no face (every vertex of a subdivision base mesh must be "
                 "a corner of a triangle)");
    if (!base.IsBoundaryVertex(v) && base.Valence(v) < 3)
      ThrowError(source, "vertex " + std::to_string(v),
                 "interior vertex with " + std::to_string(base.Valence(v)) +
                     " neighbours (expected at least 3)");
  }

  for (int level = 0; level < levels; ++level) {
    refinement_.push_back(LoopRefinementMatrix(topology_[level]));
    refinement_stencils_.push_back(LoopRefinementStencil(topology_[level]));
    faces_.push_back(SplitFaces(faces_[level], topology_[level]));
    const int next_vertex_count = topology_[level].vertex_count() + topology_[level].edge_count();
    topology_.emplace_back(faces_[level + 1], next_vertex_count,
                           source + " (level " + std::to_string(level + 1) + ")");
  }
  for (int level = 0; level <= levels; ++level) {
    taubin_.push_back(TaubinSmoothingMatrix(topology_[level], taubin));
    limit_positions_.push_back(LoopLimitPositionMatrix(topology_[level]));
    limit_tangents_.push_back(LoopLimitTangentMatrices(topology_[level]));
    tangent_stencils_.push_back(LoopLimitTangentStencil(topology_[level]));
    if (level > 0) {
      SparseMatrix coarsening = taubin_[level].topRows(topology_[level - 1].vertex_count());
      coarsening.makeCompressed();
      coarsening_.push_back(std::move(coarsening));
    }
  }
  for (int level = 1; level <= levels; ++level)
    synthesis_plans_.push_back(BuildSynthesisPlan(topology_[level - 1], topology_[level],
                                                  refinement_stencils_[level - 1],
                                                  tangent_stencils_[level]));
}

bool LoopHierarchy::IsOddVertex(int level, int vertex) const {
  SUBFLOW_CHECK(level >= 1 && level <= finest_level(), "level out of range");
  SUBFLOW_CHECK(vertex >= 0 && vertex < VertexCount(level), "vertex out of range");
  return vertex >= VertexCount(level - 1);
}

std::array<int, 2> LoopHierarchy::ParentEdge(int level, int vertex) const {
  SUBFLOW_CHECK(IsOddVertex(level, vertex), "ParentEdge needs an odd vertex");
  const MeshTopology& parent = topology_[level - 1];
  const int edge = vertex - parent.vertex_count();
  return {parent.EdgeVertex(edge, 0), parent.EdgeVertex(edge, 1)};
}

Eigen::Vector3d LoopHierarchy::ChildToParentBarycentric(int child_index,
                                                        const Eigen::Vector3d& w) {
  SUBFLOW_CHECK(child_index >= 0 && child_index < 4, "child index out of range");
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  if (child_index == 3) {
    for (int j = 0; j < 3; ++j) u += w[j] * 0.5 * (identity.col(j) + identity.col((j + 1) % 3));
    return u;
  }
  const int k = child_index;
  for (int j = 0; j < 3; ++j)
    u += j == k ? Eigen::Vector3d(w[j] * identity.col(k))
                : Eigen::Vector3d(w[j] * 0.5 * (identity.col(k) + identity.col(j)));
  return u;
}

int LoopHierarchy::ParentToChildBarycentric(const Eigen::Vector3d& u, Eigen::Vector3d* w) {
  for (int k = 0; k < 3; ++k) {
    if (u[k] >= 0.5) {  // corner child k: u_j = w_j / 2 for j ≠ k
      *w = 2.0 * u;
      (*w)[k] = 2.0 * u[k] - 1.0;
      return k;
    }
  }
  // Centre child: u_0 = (w_0 + w_2)/2, u_1 = (w_0 + w_1)/2, u_2 = (w_1 + w_2)/2.
  *w = Eigen::Vector3d(1.0 - 2.0 * u[2], 1.0 - 2.0 * u[0], 1.0 - 2.0 * u[1]);
  return 3;
}

Positions LoopHierarchy::Refine(const Positions& control_points, int from_level,
                                int to_level) const {
  SUBFLOW_CHECK(0 <= from_level && from_level <= to_level && to_level <= finest_level(),
                "levels out of range");
  SUBFLOW_CHECK(control_points.rows() == VertexCount(from_level),
                "control points do not match the level's vertex count");
  Positions c = control_points, next;
  for (int level = from_level; level < to_level; ++level) {
    refinement_stencils_[level].Apply(c, &next);
    c.swap(next);
  }
  return c;
}

}  // namespace subflow::geometry
