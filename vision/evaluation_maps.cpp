#include "vision/evaluation_maps.h"

#include <optional>

#include "geometry/closest_point.h"
#include "geometry/vertex_normals.h"
#include "vision/evaluation_visibility.h"

namespace subflow::vision {
namespace {

double Signed(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d d = to - from;
  return d.dot(normal) < 0.0 ? -d.norm() : d.norm();
}

Eigen::VectorXi Views(const std::optional<SurfaceVisibility>& visibility, const geometry::Positions& points) {
  if (!visibility) return Eigen::VectorXi::Constant(points.rows(), -1);
  const std::vector<int> counts = visibility->ViewCounts(points);
  return Eigen::Map<const Eigen::VectorXi>(counts.data(), static_cast<Eigen::Index>(counts.size()));
}

}  // namespace

FrameErrorMaps ComputeErrorMaps(const geometry::TriangleMesh& truth, const geometry::TriangleMesh& result,
                                const std::vector<Camera>& cameras, double visibility_tolerance) {
  const geometry::ClosestPointTree truth_tree(truth, "ground truth");
  const geometry::ClosestPointTree result_tree(result, "result");
  std::optional<SurfaceVisibility> visibility;
  if (!cameras.empty()) visibility.emplace(cameras, truth, visibility_tolerance);
  FrameErrorMaps maps;

  const std::vector<geometry::SurfacePoint> on_truth = truth_tree.ClosestPoints(result.V);
  const geometry::Positions face_normals = geometry::FaceNormals(truth.V, truth.F);
  geometry::Positions closest(result.V.rows(), 3);
  maps.result.error.resize(result.V.rows());
  for (Eigen::Index i = 0; i < result.V.rows(); ++i) {
    closest.row(i) = on_truth[i].point.transpose();
    maps.result.error[i] = Signed(on_truth[i].point, result.V.row(i).transpose(),
                                  face_normals.row(on_truth[i].face).transpose());
  }
  maps.result.views = Views(visibility, closest);

  const std::vector<geometry::SurfacePoint> on_result = result_tree.ClosestPoints(truth.V);
  const geometry::Positions vertex_normals = geometry::VertexNormals(truth.V, truth.F);
  maps.truth.error.resize(truth.V.rows());
  for (Eigen::Index i = 0; i < truth.V.rows(); ++i)
    maps.truth.error[i] = Signed(truth.V.row(i).transpose(), on_result[i].point, vertex_normals.row(i).transpose());
  maps.truth.views = Views(visibility, truth.V);
  return maps;
}

}  // namespace subflow::vision
