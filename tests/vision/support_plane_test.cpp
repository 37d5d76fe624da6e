// The support plane under an object (vision/support_plane.h): found under points of a
// floor and of an object standing on it, refused where no plane carries the object.
#include "vision/support_plane.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"

namespace subflow::vision {
namespace {

// Points of the floor z = floor_z (a 1 m square) and of a sphere of radius 0.2 standing
// on it, each with uniform noise of ±noise.
std::vector<Eigen::Vector3d> FloorAndSphere(int floor_points, int sphere_points, double floor_z, double noise,
                                            unsigned seed = 3) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < floor_points; ++i)
    points.emplace_back(0.5 * unit(random), 0.5 * unit(random), floor_z + noise * unit(random));
  for (int i = 0; i < sphere_points; ++i) {
    Eigen::Vector3d direction(unit(random), unit(random), unit(random));
    if (direction.norm() < 1e-3) continue;
    points.push_back(Eigen::Vector3d(0, 0, floor_z + 0.2) + (0.2 + noise * unit(random)) * direction.normalized());
  }
  return points;
}

TEST(SupportPlane, FindsTheFloorUnderAnObjectAndOrientsItTowardsTheCameras) {
  const std::vector<Eigen::Vector3d> points = FloorAndSphere(3000, 3000, -0.13, 0.002);
  const SupportPlane plane = FindSupportPlane(points, Eigen::Vector3d(0.3, -1.0, 0.5), 0.005);
  ASSERT_TRUE(plane.found) << plane.Describe();
  // The normal points up (the cameras are above the floor), the plane passes through z = −0.13
  // to the noise (±2 mm, least squares over ~3000 inliers).
  EXPECT_GT(plane.normal.z(), 0.999) << plane.Describe();
  EXPECT_NEAR(plane.SignedDistance(Eigen::Vector3d(0.1, 0.2, -0.13)), 0.0, 5e-4) << plane.Describe();
  // Every floor point is an inlier; the sphere adds the few points of its cap within 5 mm.
  EXPECT_GE(plane.inliers, 3000);
  EXPECT_LT(plane.inliers, 3300);
  EXPECT_GT(plane.above_fraction, 0.99);
}

TEST(SupportPlane, RefusesAPlaneWithTheObjectOnBothSides) {
  // A slab of points around z = 0 (the middle of an object, e.g. a flat disk) with the
  // rest of the object above and below it: it is not what the object stands on.
  std::vector<Eigen::Vector3d> points = FloorAndSphere(3000, 0, 0.0, 0.002);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 2000; ++i) points.emplace_back(0.2 * unit(random), 0.2 * unit(random), 0.3 * unit(random));
  const SupportPlane plane = FindSupportPlane(points, Eigen::Vector3d(0, 0, 2), 0.005);
  EXPECT_FALSE(plane.found) << plane.Describe();
  EXPECT_LT(plane.above_fraction, 0.9);
}

TEST(SupportPlane, RefusesAPlaneOfTooFewPoints) {
  // A sphere alone: the best "plane" holds a thin band of it, under min_inlier_fraction.
  const std::vector<Eigen::Vector3d> points = FloorAndSphere(0, 5000, 0.0, 0.0005);
  SupportPlaneOptions options;
  options.min_inlier_fraction = 0.05;
  const SupportPlane plane = FindSupportPlane(points, Eigen::Vector3d(0, 0, 2), 0.001, options);
  EXPECT_FALSE(plane.found) << plane.Describe();
}

TEST(SupportPlane, SameResultForTheSameSeed) {
  const std::vector<Eigen::Vector3d> points = FloorAndSphere(2000, 2000, 0.1, 0.003);
  const SupportPlane a = FindSupportPlane(points, Eigen::Vector3d(0, 0, 3), 0.006);
  const SupportPlane b = FindSupportPlane(points, Eigen::Vector3d(0, 0, 3), 0.006);
  EXPECT_EQ(a.normal, b.normal);
  EXPECT_EQ(a.offset, b.offset);
}

TEST(SupportPlane, BadOptionsAndTolerancesAreErrors) {
  const std::vector<Eigen::Vector3d> points = FloorAndSphere(100, 100, 0.0, 0.001);
  EXPECT_THROW(FindSupportPlane(points, Eigen::Vector3d::Zero(), 0.0), Error);
  EXPECT_THROW(FindSupportPlane(points, Eigen::Vector3d::Zero(), std::nan("")), Error);
  SupportPlaneOptions options;
  options.min_above_fraction = 1.5;
  EXPECT_THROW(FindSupportPlane(points, Eigen::Vector3d::Zero(), 0.01, options), Error);
}

}  // namespace
}  // namespace subflow::vision
