// Claims of vision/voxel_morphology.h: the separable box passes equal their brute-force
// definition; opening and closing remove noise and fill holes of one voxel and keep an
// object cut by the border; components and cavities do what their definitions say.
#include "vision/voxel_morphology.h"

#include <random>

#include <Eigen/Core>
#include <gtest/gtest.h>

namespace subflow::vision {
namespace {

using geometry::ScalarVolume;

ScalarVolume Volume(int n) { return ScalarVolume(Eigen::Vector3d::Zero(), 1.0, n, n, n, 0.0f); }

void FillBox(ScalarVolume* v, int lo, int hi, float value = 1.0f) {  // [lo, hi)³
  for (int k = lo; k < hi; ++k)
    for (int j = lo; j < hi; ++j)
      for (int i = lo; i < hi; ++i) v->at(i, j, k) = value;
}

TEST(VoxelMorphology, SeparableBoxPassesEqualBruteForce) {
  ScalarVolume random(Eigen::Vector3d::Zero(), 1.0, 21, 17, 13);
  std::mt19937 rng(11);
  for (float& value : random.values) value = (rng() % 100) < 20 ? 1.0f : 0.0f;
  for (int r : {1, 2}) {
    ScalarVolume dilated = random, eroded = random;
    DilateBox(&dilated, r);
    ErodeBox(&eroded, r);
    size_t dilate_errors = 0, erode_errors = 0;
    for (int k = 0; k < random.nz; ++k)
      for (int j = 0; j < random.ny; ++j)
        for (int i = 0; i < random.nx; ++i) {
          bool any = false, all = true;  // outside: empty for dilation, occupied for erosion
          for (int dk = -r; dk <= r; ++dk)
            for (int dj = -r; dj <= r; ++dj)
              for (int di = -r; di <= r; ++di) {
                if (!random.InRange(i + di, j + dj, k + dk)) continue;
                const bool on = random.at(i + di, j + dj, k + dk) > 0.5f;
                any = any || on;
                all = all && on;
              }
          dilate_errors += (dilated.at(i, j, k) > 0.5f) != any;
          erode_errors += (eroded.at(i, j, k) > 0.5f) != all;
        }
    EXPECT_EQ(dilate_errors, 0u) << "radius " << r;
    EXPECT_EQ(erode_errors, 0u) << "radius " << r;
  }
}

TEST(VoxelMorphology, OpeningRemovesNoiseVoxelClosingFillsOneVoxelHole) {
  ScalarVolume cube = Volume(30);
  FillBox(&cube, 8, 22);
  ScalarVolume noisy = cube;
  noisy.at(15, 15, 15) = 0.0f;  // one-voxel hole inside
  noisy.at(15, 8, 15) = 0.0f;   // one-voxel pit in the surface
  noisy.at(3, 3, 3) = 1.0f;     // isolated noise voxel
  noisy.at(15, 22, 15) = 1.0f;  // one-voxel bump on the surface
  CloseBox(&noisy, 1);
  OpenBox(&noisy, 1);
  EXPECT_EQ(noisy.values, cube.values);  // exact: the 14³ cube is open and closed for r = 1
}

TEST(VoxelMorphology, ClosingAndOpeningKeepAnObjectCutByTheBorder) {
  ScalarVolume slab = Volume(12);
  for (int k = 0; k < 12; ++k)
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 5; ++i) slab.at(i, j, k) = 1.0f;  // touches five faces
  ScalarVolume closed = slab, opened = slab;
  CloseBox(&closed, 2);
  OpenBox(&opened, 2);
  EXPECT_EQ(closed.values, slab.values);
  EXPECT_EQ(opened.values, slab.values);
}

TEST(VoxelMorphology, ComponentsKeepTheBigObject) {
  ScalarVolume volume = Volume(30);
  FillBox(&volume, 10, 20);  // 1000 voxels
  ScalarVolume big_only = volume;
  FillBox(&volume, 2, 4);  // 8 voxels, far away
  const ComponentSummary summary = KeepLargeComponents(&volume, 0.1);
  EXPECT_EQ(summary.found, 2);
  EXPECT_EQ(summary.kept, 1);
  EXPECT_EQ(summary.largest, 1000u);
  EXPECT_EQ(summary.removed_voxels, 8u);
  EXPECT_EQ(volume.values, big_only.values);

  // Two cubes touching at one corner: one component in 26-connectivity, two in 6.
  ScalarVolume corners = Volume(10);
  FillBox(&corners, 1, 4);
  FillBox(&corners, 4, 7);
  ScalarVolume copy = corners;
  EXPECT_EQ(KeepLargeComponents(&corners, 0.0, 26).found, 1);
  EXPECT_EQ(KeepLargeComponents(&copy, 0.0, 6).found, 2);
}

TEST(VoxelMorphology, InteriorCavitiesAreFilledOpenOnesAreNot) {
  ScalarVolume shell = Volume(20);
  FillBox(&shell, 4, 16);
  FillBox(&shell, 7, 13, 0.0f);  // 6³ = 216 empty voxels enclosed
  ScalarVolume solid = Volume(20);
  FillBox(&solid, 4, 16);
  EXPECT_EQ(FillCavities(&shell), 216u);
  EXPECT_EQ(shell.values, solid.values);

  ScalarVolume open = Volume(20);
  FillBox(&open, 4, 16);
  FillBox(&open, 7, 13, 0.0f);
  for (int i = 0; i < 7; ++i) open.at(i, 10, 10) = 0.0f;  // a tunnel to the border
  EXPECT_EQ(FillCavities(&open), 0u);
}

}  // namespace
}  // namespace subflow::vision
