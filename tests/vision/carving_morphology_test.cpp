// The carving's morphology on grids coarser than the automatic one
// (vision/voxel_carving.h: ResolveCarvingOptions): radii narrowed by the grid's spacing
// against the automatic one, and a thin part that a 3-voxel opening would remove kept.
#include <cmath>
#include <cstdio>
#include <utility>

#include <gtest/gtest.h>

#include "tests/vision/carving_test_rig.h"
#include "vision/silhouettes.h"
#include "vision/voxel_carving.h"

namespace subflow::vision {
namespace {

using namespace carving_rig;

// Mask of a sphere with a thin rod (a capsule from `a` to `b` of radius `rod`) sticking out
// of it: pixel centres whose ray passes the rod's axis within `rod` (the axis sampled every
// 0.2 mm) or meets the sphere.
cv::Mat SphereWithRodMask(const Camera& camera, const Sphere& sphere, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b, double rod) {
  cv::Mat mask = SphereMask(camera, sphere);
  const int samples = static_cast<int>(std::ceil((b - a).norm() / 2e-4));
  for (int y = 0; y < camera.height(); ++y)
    for (int x = 0; x < camera.width(); ++x) {
      const Eigen::Vector3d d = camera.BackProject(Eigen::Vector2d(x, y)).normalized();
      for (int s = 0; s <= samples; ++s) {
        const Eigen::Vector3d v = a + (b - a) * (double(s) / samples) - camera.Center();
        if ((v - v.dot(d) * d).norm() <= rod) {
          mask.at<uint8_t>(y, x) = 255;
          break;
        }
      }
    }
  return mask;
}

// The points of the rod's axis (x = 0.03 … 0.12 every 1 cm, off the sphere) inside the
// carved hull's iso-surface at ½, and how many were tested.
std::pair<int, int> RodAxisOccupied(const CarvingResult& result) {
  int occupied = 0, total = 0;
  for (double x = 0.03; x <= 0.12; x += 0.01, ++total) occupied += TrilinearOccupancy(result.occupancy, {x, 0, 0}) >= 0.5;
  return {occupied, total};
}

TEST(VoxelCarving, MorphologyIsNarrowedOnlyOnGridsCoarserThanTheAutomaticOne) {
  const std::vector<Camera> cameras = SixCameras();
  VoxelCarvingOptions options;  // automatic: 2 px per voxel at ≈ 333 px/m → 6 mm, 50 voxels
  options.closing_radius = options.opening_radius = 1;
  const double automatic = AutomaticVoxelSpacing(cameras, kBounds, options);
  EXPECT_NEAR(automatic, 2.0 / (200.0 / 0.6), 1e-3 * automatic);
  const VoxelCarvingOptions on_automatic = ResolveCarvingOptions(cameras, kBounds, options);
  EXPECT_EQ(on_automatic.resolution, ChooseResolution(cameras, kBounds, options));
  EXPECT_EQ(on_automatic.closing_radius, 1);
  EXPECT_EQ(on_automatic.opening_radius, 1);
  options.resolution = 100;  // finer: unchanged
  EXPECT_EQ(ResolveCarvingOptions(cameras, kBounds, options).opening_radius, 1);
  options.resolution = 30;  // 1.7× coarser: a 3-voxel box spans 10 px instead of 6; ⌊0.6 + ½⌋ = 1
  EXPECT_EQ(ResolveCarvingOptions(cameras, kBounds, options).opening_radius, 1);
  options.resolution = 20;  // 2.5× coarser: ⌊0.4 + ½⌋ = 0
  EXPECT_EQ(ResolveCarvingOptions(cameras, kBounds, options).closing_radius, 0);
  EXPECT_EQ(ResolveCarvingOptions(cameras, kBounds, options).opening_radius, 0);
  options.resolution = 12;
  options.closing_radius = options.opening_radius = 3;  // ⌊3 · 0.24 + ½⌋ = 1
  EXPECT_EQ(ResolveCarvingOptions(cameras, kBounds, options).opening_radius, 1);
  // No camera sees the volume's centre: nothing to measure the grid against, unchanged.
  const Bounds away{Eigen::Vector3d(-0.15, -0.15, 4.85), Eigen::Vector3d(0.15, 0.15, 5.15)};  // above every view
  EXPECT_EQ(AutomaticVoxelSpacing(cameras, away, options), 0.0);
  EXPECT_EQ(ResolveCarvingOptions(cameras, away, options).opening_radius, 3);
  // Automatic radii stay automatic, unless even radius 1 narrows to 0.
  options.closing_radius = options.opening_radius = -1;
  options.resolution = 30;
  EXPECT_EQ(ResolveCarvingOptions(cameras, kBounds, options).opening_radius, -1);
  options.resolution = 20;
  EXPECT_EQ(ResolveCarvingOptions(cameras, kBounds, options).closing_radius, 0);
  EXPECT_EQ(ResolveCarvingOptions(cameras, kBounds, options).opening_radius, 0);
}

// A rod 16 mm thick sticking out of a sphere, carved on a grid of 25 mm voxels (4× coarser
// than the automatic 6 mm, as the 160-voxel cap makes a room-sized volume): the rod is
// about two voxels across, so an opening by a 3-voxel box removes it; the resolved options
// keep it (every voxel on its axis is occupied) and keep the sphere.
TEST(VoxelCarving, ThinPartOnACoarseGridSurvivesTheResolvedMorphology) {
  const std::vector<Camera> cameras = SixCameras();
  Sphere sphere;
  sphere.centre = Eigen::Vector3d(-0.04, 0, 0);
  sphere.radius = 0.06;
  const Eigen::Vector3d a(0.0, 0.0, 0.0), b(0.13, 0.0, 0.0);
  std::vector<Silhouette> silhouettes;
  for (const Camera& camera : cameras)
    silhouettes.push_back(SilhouetteFromMask(SphereWithRodMask(camera, sphere, a, b, 0.008)));
  VoxelCarvingOptions options;
  options.resolution = 12;
  options.closing_radius = options.opening_radius = 1;
  options.compute_silhouette_iou = false;
  const VoxelCarvingOptions resolved = ResolveCarvingOptions(cameras, kBounds, options);
  ASSERT_EQ(resolved.opening_radius, 0);
  const CarvingResult kept = CarveVoxels(cameras, silhouettes, kBounds, resolved);
  const auto [kept_on_axis, axis_points] = RodAxisOccupied(kept);
  EXPECT_EQ(kept_on_axis, axis_points) << "points of the rod's axis outside the hull carved with the resolved options";
  EXPECT_GE(TrilinearOccupancy(kept.occupancy, sphere.centre), 0.5);
  EXPECT_EQ(kept.opening_radius, 0);
  // The same grid with the box sized for the automatic grid: the rod is gone.
  const CarvingResult opened = CarveVoxels(cameras, silhouettes, kBounds, options);
  const auto [opened_on_axis, unused] = RodAxisOccupied(opened);
  EXPECT_LE(opened_on_axis, 2) << "the 3-voxel opening was expected to remove the 2-voxel rod";
  EXPECT_EQ(opened.opening_radius, 1);
  std::printf("[ figures ] rod axis points occupied: %d of %d with the resolved morphology, %d with radius 1\n",
              kept_on_axis, axis_points, opened_on_axis);
}

// Automatic radii: the hull of masks is not cleaned, the hull of measured silhouettes is.
// A rod 8 mm thick (1.3 voxels of the automatic 6 mm grid) sticking out of a sphere: with
// masks it is kept; the same outlines as background differences are opened by a 3-voxel
// box, which removes it.
TEST(VoxelCarving, OnlyMeasuredSilhouettesAreCleanedAutomatically) {
  const std::vector<Camera> cameras = SixCameras();
  Sphere sphere;
  sphere.centre = Eigen::Vector3d(-0.04, 0, 0);
  sphere.radius = 0.06;
  const Eigen::Vector3d a(0.0, 0.0, 0.0), b(0.13, 0.0, 0.0);
  std::vector<Silhouette> masks, measured;
  for (const Camera& camera : cameras) {
    masks.push_back(SilhouetteFromMask(SphereWithRodMask(camera, sphere, a, b, 0.004)));
    measured.push_back(masks.back());
    measured.back().source = EvidenceSource::kBackground;
  }
  VoxelCarvingOptions options;
  options.compute_silhouette_iou = false;
  EXPECT_EQ(options.closing_radius, -1);
  EXPECT_EQ(options.opening_radius, -1);
  const VoxelCarvingOptions resolved = ResolveCarvingOptions(cameras, kBounds, options);
  const CarvingResult of_masks = CarveVoxels(cameras, masks, kBounds, resolved);
  const CarvingResult of_measured = CarveVoxels(cameras, measured, kBounds, resolved);
  EXPECT_EQ(of_masks.closing_radius, 0);
  EXPECT_EQ(of_masks.opening_radius, 0);
  EXPECT_EQ(of_measured.closing_radius, 1);
  EXPECT_EQ(of_measured.opening_radius, 1);
  EXPECT_GE(RodAxisOccupied(of_masks).first, 9);
  EXPECT_LE(RodAxisOccupied(of_measured).first, 2);
  EXPECT_GE(TrilinearOccupancy(of_measured.occupancy, sphere.centre), 0.5);
  std::printf("[ figures ] rod axis points occupied: %d of 10 from masks, %d from the same outlines measured\n",
              RodAxisOccupied(of_masks).first, RodAxisOccupied(of_measured).first);
}

}  // namespace
}  // namespace subflow::vision
