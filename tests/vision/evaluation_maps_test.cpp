// Per-vertex error maps (vision/evaluation_maps.h): signs and sizes on surfaces whose
// distances are known (concentric spheres), and view counts on a plane half seen.
#include "vision/evaluation_maps.h"

#include <gtest/gtest.h>

#include "geometry/icosphere.h"
#include "vision/camera_rig.h"

namespace subflow::vision {
namespace {

using geometry::TriangleMesh;

TEST(ErrorMaps, ResultOutsideTheTruthIsPositiveOnBothSides) {
  const TriangleMesh truth = geometry::MakeIcosphere(4, 0.1);
  const TriangleMesh outside = geometry::MakeIcosphere(4, 0.103);  // 3 mm outside
  const FrameErrorMaps maps = ComputeErrorMaps(truth, outside, {}, 0.001);
  ASSERT_EQ(maps.result.error.size(), outside.vertex_count());
  ASSERT_EQ(maps.truth.error.size(), truth.vertex_count());
  // The flat facets of the spheres lie within 0.3 mm of their radius at these levels.
  EXPECT_NEAR(maps.result.error.minCoeff(), 0.003, 3e-4);
  EXPECT_NEAR(maps.result.error.maxCoeff(), 0.003, 3e-4);
  EXPECT_NEAR(maps.truth.error.minCoeff(), 0.003, 3e-4);
  EXPECT_NEAR(maps.truth.error.maxCoeff(), 0.003, 3e-4);
  EXPECT_EQ(maps.result.views.maxCoeff(), -1);  // no cameras: not computed

  const TriangleMesh inside = geometry::MakeIcosphere(4, 0.096);  // 4 mm inside
  const FrameErrorMaps shrunk = ComputeErrorMaps(truth, inside, {}, 0.001);
  EXPECT_NEAR(shrunk.result.error.maxCoeff(), -0.004, 3e-4);
  EXPECT_NEAR(shrunk.truth.error.minCoeff(), -0.004, 3e-4);
}

// A closed shell: the sphere of radius `outer` and, turned inside out, the one of radius
// `inner` (a hollow ball with a wall of outer − inner).
TriangleMesh HollowBall(double outer, double inner) {
  const TriangleMesh a = geometry::MakeIcosphere(4, outer), b = geometry::MakeIcosphere(4, inner);
  TriangleMesh shell;
  shell.V.resize(a.V.rows() + b.V.rows(), 3);
  shell.V << a.V, b.V;
  shell.F.resize(a.F.rows() + b.F.rows(), 3);
  shell.F.topRows(a.F.rows()) = a.F;
  for (Eigen::Index f = 0; f < b.F.rows(); ++f)
    shell.F.row(a.F.rows() + f) << b.F(f, 0) + a.V.rows(), b.F(f, 2) + a.V.rows(), b.F(f, 1) + a.V.rows();
  return shell;
}

TEST(ErrorMaps, AHollowCappedByTheResultIsPositiveOnTheTruthSide) {
  // The truth is a hollow ball (wall 10 mm), the result the solid ball: the result covers
  // the hollow. The nearest result point of the hollow's wall lies through the wall (10 mm
  // outward, against the wall's normal), yet the result is outside the truth there.
  const TriangleMesh truth = HollowBall(0.1, 0.09);
  const TriangleMesh solid = geometry::MakeIcosphere(4, 0.1);
  const FrameErrorMaps maps = ComputeErrorMaps(truth, solid, {}, 0.001);
  const Eigen::Index outer_vertices = solid.V.rows();
  for (Eigen::Index v = outer_vertices; v < truth.V.rows(); ++v)
    EXPECT_NEAR(maps.truth.error[v], 0.01, 3e-4) << v;
  // The other way round, the result's hollow is a dent inside the solid truth.
  const FrameErrorMaps hollow = ComputeErrorMaps(solid, truth, {}, 0.001);
  for (Eigen::Index v = outer_vertices; v < truth.V.rows(); ++v)
    EXPECT_NEAR(hollow.result.error[v], -0.01, 3e-4) << v;
}

TEST(ErrorMaps, ViewsCountTheCamerasThatSeeTheTruePoint) {
  const TriangleMesh truth = geometry::MakeIcosphere(3, 0.1);
  // One camera 1 m away on +z: it sees the upper half of the sphere, not the lower.
  const std::vector<Camera> cameras = {LookAtCamera("top", 400, 400, 800.0, {0, 0, 1.0}, {0, 0, 0})};
  const FrameErrorMaps maps = ComputeErrorMaps(truth, truth, cameras, 0.001);
  for (Eigen::Index v = 0; v < truth.V.rows(); ++v) {
    if (truth.V(v, 2) > 0.02) {
      EXPECT_EQ(maps.truth.views[v], 1) << v;
    }
    if (truth.V(v, 2) < -0.02) {
      EXPECT_EQ(maps.truth.views[v], 0) << v;
    }
    EXPECT_NEAR(maps.truth.error[v], 0.0, 1e-9);
  }
}

}  // namespace
}  // namespace subflow::vision
