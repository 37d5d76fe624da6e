// Claims about vision/working_scale.h: a working camera projects every point where the
// resized image shows it (pixel-centre convention, distortion kept), masks stay binary,
// and the scales follow the voxel's and the surface's pixel footprints, never above 1.
#include "vision/working_scale.h"

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace subflow::vision {
namespace {

Camera TestCamera(const Eigen::VectorXd& distortion = Eigen::VectorXd()) {
  Eigen::Matrix3d K;
  K << 900.0, 0.0, 541.3, 0.0, 905.0, 955.2, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.1, 1.0, -0.3).normalized()).toRotationMatrix();
  return Camera("cam", 1088, 1920, K, R, Eigen::Vector3d(0.1, -0.05, 3.0), distortion);
}

TEST(WorkingScale, ScaledCameraProjectsWhereTheResizedPixelIs) {
  Eigen::VectorXd distortion(5);
  distortion << -0.12, 0.03, 0.001, -0.0005, 0.0;
  for (const Camera& camera : {TestCamera(), TestCamera(distortion)}) {
    const Camera scaled = ScaledCamera(camera, 0.3);
    EXPECT_EQ(scaled.width(), 326);  // round(1088 · 0.3)
    EXPECT_EQ(scaled.height(), 576);
    EXPECT_EQ(scaled.HasDistortion(), camera.HasDistortion());
    const double a = 326.0 / 1088.0, b = 576.0 / 1920.0;
    for (const Eigen::Vector3d& X : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.4, -0.7, 0.2),
                                     Eigen::Vector3d(-0.5, 0.6, -0.3)}) {
      const Eigen::Vector2d p = camera.Project(X), q = scaled.Project(X);
      EXPECT_NEAR(q.x(), a * (p.x() + 0.5) - 0.5, 1e-9);
      EXPECT_NEAR(q.y(), b * (p.y() + 0.5) - 0.5, 1e-9);
    }
  }
  EXPECT_EQ(ScaledCamera(TestCamera(), 1.0).K(), TestCamera().K());
}

TEST(WorkingScale, ResizedImageShowsADotWhereTheWorkingCameraProjectsIt) {
  const Camera camera = TestCamera();
  const Camera scaled = ScaledCamera(camera, 0.25);
  const Eigen::Vector3d X(0.3, -0.2, 0.1);
  const Eigen::Vector2d p = camera.Project(X);
  cv::Mat image = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
  constexpr int kShift = 4;  // sub-pixel centre: coordinates in 1/16 px
  cv::circle(image, cv::Point(static_cast<int>(std::lround(p.x() * 16)), static_cast<int>(std::lround(p.y() * 16))),
             24 * 16, cv::Scalar(255), cv::FILLED, cv::LINE_AA, kShift);
  const cv::Mat resized = ResizeToCamera(image, scaled);
  ASSERT_EQ(resized.cols, scaled.width());
  ASSERT_EQ(resized.rows, scaled.height());
  const cv::Moments m = cv::moments(resized);
  const Eigen::Vector2d q = scaled.Project(X);
  EXPECT_NEAR(m.m10 / m.m00, q.x(), 0.05);
  EXPECT_NEAR(m.m01 / m.m00, q.y(), 0.05);
  // A mask stays 0 / 255.
  const cv::Mat mask = ResizeToCamera(image, scaled, true);
  EXPECT_EQ(cv::countNonZero((mask != 0) & (mask != 255)), 0);
  EXPECT_GT(cv::countNonZero(mask), 0);
  // Same size: the image itself.
  EXPECT_EQ(ResizeToCamera(image, camera).data, image.data);
}

TEST(WorkingScale, EvidenceScaleFollowsTheVoxelFootprint) {
  Eigen::Matrix3d K;
  K << 1000.0, 0.0, 500.0, 0.0, 1000.0, 500.0, 0.0, 0.0, 1.0;
  const Camera camera("c", 1000, 1000, K, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 2.0));
  Bounds bounds;
  bounds.min = Eigen::Vector3d(-0.5, -0.5, -0.5);
  bounds.max = Eigen::Vector3d(0.5, 0.5, 0.5);
  // A 2 cm voxel at depth 2 spans 10 px: 4 px asked for → 0.4.
  EXPECT_NEAR(EvidenceScale(camera, bounds, 0.02, 4.0), 0.4, 1e-12);
  EXPECT_EQ(EvidenceScale(camera, bounds, 0.002, 4.0), 1.0);  // 1 px: never enlarged
  EXPECT_EQ(EvidenceScale(camera, bounds, 0.02, 0.0), 1.0);   // off
}

TEST(WorkingScale, SurfaceScaleFollowsTheMedianProjectedEdge) {
  Eigen::Matrix3d K;
  K << 1000.0, 0.0, 500.0, 0.0, 1000.0, 500.0, 0.0, 0.0, 1.0;
  const Camera camera("c", 1000, 1000, K, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 2.0));
  // A grid of 1 cm squares (two triangles each) facing the camera at depth 2: axis edges
  // project to 5 px, the diagonals to 7.1 px; the median is an axis edge.
  const int n = 10;
  geometry::Positions V((n + 1) * (n + 1), 3);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) V.row(i * (n + 1) + j) << 0.01 * i - 0.05, 0.01 * j - 0.05, 0.0;
  geometry::Faces F(2 * n * n, 3);
  for (int i = 0, f = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int v = i * (n + 1) + j;
      F.row(f++) << v, v + n + 1, v + 1;
      F.row(f++) << v + 1, v + n + 1, v + n + 2;
    }
  double median = 0;
  EXPECT_NEAR(SurfaceScale(camera, V, F, 2.0, &median), 0.4, 1e-9);
  EXPECT_NEAR(median, 5.0, 1e-9);
  EXPECT_EQ(SurfaceScale(camera, V, F, 8.0), 1.0);
  // Behind the camera: nothing seen, scale 1.
  geometry::Positions behind = V;
  behind.col(2).array() -= 5.0;
  EXPECT_EQ(SurfaceScale(camera, behind, F, 2.0, &median), 1.0);
  EXPECT_EQ(median, 0.0);
}

}  // namespace
}  // namespace subflow::vision
