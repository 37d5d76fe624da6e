// The lingua franca of subflow's geometry: Eigen matrices, rows = elements.
//   V  #V×3 double, vertex positions (world units, usually metres)
//   F  #F×3 int, triangles as vertex indices, counter-clockwise seen from outside
//      (so the face normal (v1−v0)×(v2−v0) points out of a closed surface).
#pragma once

#include <Eigen/Core>

namespace subflow::geometry {

using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct TriangleMesh {
  Positions V;
  Faces F;

  int vertex_count() const { return static_cast<int>(V.rows()); }
  int face_count() const { return static_cast<int>(F.rows()); }
};

}  // namespace subflow::geometry
