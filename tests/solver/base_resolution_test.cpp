#include "solver/shape/base_resolution.h"

#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "geometry/closest_point.h"
#include "geometry/isosurface.h"
#include "solver/shape/shape_init.h"
#include "vision/camera_rig.h"

namespace subflow::solver {
namespace {

constexpr double kVoxel = 0.003;  // world units (m) per voxel

// A ball (radius 14 voxels, 42 mm) with a plate 2 voxels (6 mm) thick standing 12 voxels off
// its side, as an occupancy iso-surface: the hull of a head with an ear.
geometry::TriangleMesh BallWithPlate() {
  geometry::ScalarVolume volume(Eigen::Vector3d::Constant(-32 * kVoxel), kVoxel, 64, 64, 64, 0.0f);
  for (int k = 0; k < 64; ++k)
    for (int j = 0; j < 64; ++j)
      for (int i = 0; i < 64; ++i) {
        const Eigen::Vector3d p(i - 31.7, j - 32.2, k - 31.9);
        const bool plate = std::abs(p.x()) < 1.0 && p.y() > 0.0 && p.y() < 26.0 && std::abs(p.z()) < 9.0;
        volume.at(i, j, k) = p.norm() < 14.0 || plate ? 1.0f : 0.0f;
      }
  return geometry::ExtractIsosurface(volume, geometry::IsosurfaceOptions());
}

// A ring of 8 cameras 0.6 m away; `scale` multiplies the image size and the focal length.
std::vector<vision::Camera> Ring(double scale) {
  vision::CameraRigOptions rig;
  rig.camera_count = 8;
  rig.width = static_cast<int>(320 * scale);
  rig.height = static_cast<int>(240 * scale);
  rig.focal = 420 * scale;
  return vision::MakeCameraRig(rig);
}

TEST(BaseResolution, LevelsHalveTheEdgesDownToTheTarget) {
  EXPECT_EQ(LevelsForEdge(16.3, 2.0, 6), 3);  // 2.04 px at level 3
  EXPECT_EQ(LevelsForEdge(15.9, 2.0, 6), 2);  // 3.98 px at level 2: level 3 would be below 2 px
  EXPECT_EQ(LevelsForEdge(3.0, 2.0, 6), 0);
  EXPECT_EQ(LevelsForEdge(1.0, 2.0, 6), 0);
  EXPECT_EQ(LevelsForEdge(1e6, 2.0, 6), 6);
  EXPECT_EQ(LevelsForEdge(0.0, 2.0, 6), 0);
}

TEST(BaseResolution, FinestEdgesFollowTheImagesResolutionAndTheBaseKeepsTheBound) {
  const geometry::TriangleMesh hull = BallWithPlate();
  const ShapeInitOptions options;  // distance bound 1 voxel, automatic levels, 2 px
  ASSERT_GT(options.base_distance_voxels, 0.0);
  ASSERT_EQ(options.levels, -1);
  const double t = options.finest_edge_pixels;
  int previous_levels = -1;
  for (const double scale : {1.0, 2.0, 4.0}) {
    SCOPED_TRACE(scale);
    const std::vector<vision::Camera> cameras = Ring(scale);
    const BaseResolution chosen = ChooseBaseResolution(hull, cameras, kVoxel, options, "hull");
    // The finest edges project to about t pixels: T0's faces were raised to match the levels.
    EXPECT_GT(chosen.finest_edge_pixels, 0.7 * t);
    EXPECT_LT(chosen.finest_edge_pixels, 1.4 * t);
    EXPECT_NEAR(chosen.finest_edge_pixels, MedianProjectedEdge(cameras, chosen.base.V, chosen.base.F) /
                                               std::ldexp(1.0, chosen.levels), 1e-9);
    // Twice the pixels: one more level (the same T0 faces), not a fixed count.
    if (previous_levels >= 0) {
      EXPECT_EQ(chosen.levels, previous_levels + 1);
    }
    previous_levels = chosen.levels;
    // T0 keeps the hull within the bound both ways, the plate included.
    EXPECT_TRUE(chosen.simplify.bound_kept);
    EXPECT_GE(chosen.base.face_count(), chosen.bound_face_count);
    const geometry::ClosestPointTree base_tree(chosen.base);
    EXPECT_LE(base_tree.Distances(hull.V).maxCoeff(), options.base_distance_voxels * kVoxel * (1 + 1e-9));
    std::cout << "[ figures  ] images ×" << scale << ": T0 " << chosen.base.face_count() << " faces ("
              << chosen.bound_face_count << " by the bound, edges " << chosen.bound_edge_pixels << " px), "
              << chosen.levels << " levels, finest edges " << chosen.finest_edge_pixels << " px\n";
  }
}

// HD images want many levels; the face budget bounds the finest level (T0's raise
// included), keeps the levels at most those of the unbounded choice, and the finest edges
// then project to more than the target.
TEST(BaseResolution, TheFaceBudgetBoundsTheFinestLevelOnLargeImages) {
  const geometry::TriangleMesh hull = BallWithPlate();
  ShapeInitOptions unbounded;
  unbounded.max_finest_faces = 50000000;
  const std::vector<vision::Camera> cameras = Ring(8.0);  // 2560×1920
  const BaseResolution wide = ChooseBaseResolution(hull, cameras, kVoxel, unbounded, "hull");
  ShapeInitOptions budgeted = unbounded;
  budgeted.max_finest_faces = 16384;
  ASSERT_GT(static_cast<double>(wide.base.face_count()) * std::ldexp(1.0, 2 * wide.levels), 4.0 * 16384)
      << "the unbounded choice must exceed the budget for this test to say anything";
  const BaseResolution bounded = ChooseBaseResolution(hull, cameras, kVoxel, budgeted, "hull");
  const double finest_faces = bounded.base.face_count() * std::ldexp(1.0, 2 * bounded.levels);
  std::cout << "[ figures  ] unbounded: T0 " << wide.base.face_count() << " faces, " << wide.levels
            << " levels; budget 16384: T0 " << bounded.base.face_count() << " faces, " << bounded.levels
            << " levels (" << finest_faces << " finest faces, edges " << bounded.finest_edge_pixels << " px)\n";
  EXPECT_LE(finest_faces, 16384);
  EXPECT_GE(bounded.levels, 1);  // the budget cuts the raise of T0 before it removes levels
  EXPECT_LE(bounded.levels, wide.levels);
  EXPECT_GE(bounded.base.face_count(), bounded.bound_face_count);  // the distance bound still holds
  EXPECT_GT(bounded.finest_edge_pixels, 2 * budgeted.finest_edge_pixels);
}

TEST(BaseResolution, ExplicitLevelsAndCountKeepTheOldChoice) {
  const geometry::TriangleMesh hull = BallWithPlate();
  ShapeInitOptions options;
  options.base_distance_voxels = 0;
  options.simplify.target_face_count = 200;
  options.levels = 2;
  const BaseResolution chosen = ChooseBaseResolution(hull, Ring(1.0), kVoxel, options, "hull");
  EXPECT_LE(chosen.base.face_count(), 200);
  EXPECT_GE(chosen.base.face_count(), 180);
  EXPECT_EQ(chosen.levels, 2);
  EXPECT_EQ(chosen.bound_face_count, 0);
}

}  // namespace
}  // namespace subflow::solver
