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

TEST(ErrorMaps, ViewsCountTheCamerasThatSeeTheTruePoint) {
  const TriangleMesh truth = geometry::MakeIcosphere(3, 0.1);
  // One camera 1 m away on +z: it sees the upper half of the sphere, not the lower.
  const std::vector<Camera> cameras = {LookAtCamera("top", 400, 400, 800.0, {0, 0, 1.0}, {0, 0, 0})};
  const FrameErrorMaps maps = ComputeErrorMaps(truth, truth, cameras, 0.001);
  for (Eigen::Index v = 0; v < truth.V.rows(); ++v) {
    if (truth.V(v, 2) > 0.02) {
      EXPECT_EQ(maps.truth.views[v], 1) << v;
    }
    if (truth.V(v, 2) < -0.02) EXPECT_EQ(maps.truth.views[v], 0) << v;
    EXPECT_NEAR(maps.truth.error[v], 0.0, 1e-9);
  }
}

}  // namespace
}  // namespace subflow::vision
