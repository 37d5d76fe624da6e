#include "geometry/vertex_normals.h"

#include <Eigen/Geometry>

namespace subflow::geometry {
namespace {

Eigen::Vector3d AreaVector(const Positions& V, const Faces& F, Eigen::Index f) {
  const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
  return (b - a).cross(c - a);
}

}  // namespace

Positions FaceNormals(const Positions& V, const Faces& F) {
  Positions normals(F.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d n = AreaVector(V, F, f);
    const double length = n.norm();
    normals.row(f) = length > 0.0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
  }
  return normals;
}

Positions VertexNormals(const Positions& V, const Faces& F) {
  Positions normals = Positions::Zero(V.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::RowVector3d n = AreaVector(V, F, f).transpose();
    for (int k = 0; k < 3; ++k) normals.row(F(f, k)) += n;
  }
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const double length = normals.row(v).norm();
    if (length > 0.0) normals.row(v) /= length;
  }
  return normals;
}

Eigen::VectorXd FaceAreas(const Positions& V, const Faces& F) {
  Eigen::VectorXd areas(F.rows());
  for (Eigen::Index f = 0; f < F.rows(); ++f) areas[f] = 0.5 * AreaVector(V, F, f).norm();
  return areas;
}

}  // namespace subflow::geometry
