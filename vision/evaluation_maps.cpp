#include "vision/evaluation_maps.h"

#include <cmath>
#include <optional>

#include "core/error.h"
#include "geometry/closest_point.h"
#include "geometry/mesh_topology.h"
#include "geometry/vertex_normals.h"
#include "vision/evaluation_visibility.h"

namespace subflow::vision {
namespace {

double Signed(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d d = to - from;
  return d.dot(normal) < 0.0 ? -d.norm() : d.norm();
}

// Whether `mesh` bounds a volume (closed oriented manifold), so that the inside test of
// its tree means something.
bool BoundsAVolume(const geometry::TriangleMesh& mesh) {
  try {
    return geometry::MeshTopology(mesh.F, static_cast<int>(mesh.V.rows())).IsClosed();
  } catch (const Error&) {
    return false;
  }
}

// |distance| signed by the side of `point` with respect to the closed surface of `tree`
// (`inside_sign` where it is inside); the normal test where the side is undecided (on the
// surface) or the surface bounds no volume.
double SignedBySide(const geometry::ClosestPointTree& tree, bool bounds_a_volume, const Eigen::Vector3d& point,
                    double inside_sign, double normal_signed) {
  if (bounds_a_volume) {
    const geometry::PointSide side = tree.Side(point);
    if (side == geometry::PointSide::kInside) return inside_sign * std::abs(normal_signed);
    if (side == geometry::PointSide::kOutside) return -inside_sign * std::abs(normal_signed);
  }
  return normal_signed;
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
  // The sign is the side of the point with respect to the other closed surface (a truth
  // point inside the result is covered by it: a lid over a hollow is > 0 on both sides,
  // whichever way the nearest point lies); the normal test only for open meshes.
  const bool truth_closed = BoundsAVolume(truth), result_closed = BoundsAVolume(result);
  for (Eigen::Index i = 0; i < result.V.rows(); ++i) {
    closest.row(i) = on_truth[i].point.transpose();
    const Eigen::Vector3d x = result.V.row(i).transpose();
    maps.result.error[i] = SignedBySide(truth_tree, truth_closed, x, -1.0,
                                        Signed(on_truth[i].point, x, face_normals.row(on_truth[i].face).transpose()));
  }
  maps.result.views = Views(visibility, closest);

  const std::vector<geometry::SurfacePoint> on_result = result_tree.ClosestPoints(truth.V);
  const geometry::Positions vertex_normals = geometry::VertexNormals(truth.V, truth.F);
  maps.truth.error.resize(truth.V.rows());
  for (Eigen::Index i = 0; i < truth.V.rows(); ++i) {
    const Eigen::Vector3d t = truth.V.row(i).transpose();
    maps.truth.error[i] = SignedBySide(result_tree, result_closed, t, 1.0,
                                       Signed(t, on_result[i].point, vertex_normals.row(i).transpose()));
  }
  maps.truth.views = Views(visibility, truth.V);
  return maps;
}

}  // namespace subflow::vision
