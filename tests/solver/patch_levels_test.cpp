#include "solver/stereo/patch_levels.h"

#include <algorithm>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "tests/solver/refinement_test_scene.h"

namespace subflow::solver {
namespace {

using testing::Scene;

// A patch size between the median base face's and the largest one's quarter: the median
// level is 0, and only the level-1 children of the largest base faces still cover it.
double AreaBetweenMedianAndLargest(const PatchLevels& levels) {
  std::vector<double> areas = levels.base_areas();
  std::sort(areas.begin(), areas.end());
  const double median = areas[areas.size() / 2], largest = areas.back();
  EXPECT_GT(largest, 1.05 * median);
  return 0.25 * (0.5 * median + 0.5 * largest);
}

TEST(PatchLevels, BelowTheMedianLevelOnlyPatchesThatStillCoverTheAreaAreResolved) {
  const auto& scene = Scene().scene;
  const PatchLevels probe(scene.hierarchy, scene.control, scene.cameras, 1.0, true);
  const double area = AreaBetweenMedianAndLargest(probe);
  const PatchLevels per_patch(scene.hierarchy, scene.control, scene.cameras, area, true);
  const PatchLevels median_only(scene.hierarchy, scene.control, scene.cameras, area, false);
  EXPECT_EQ(per_patch.median_level(), 0);
  EXPECT_EQ(per_patch.finest_level(), 1);
  EXPECT_EQ(median_only.finest_level(), 0);
  int resolved = 0;
  for (int f = 0; f < scene.hierarchy.FaceCount(1); ++f) {
    const bool big = per_patch.base_areas()[f / 4] / 4.0 >= area;
    EXPECT_EQ(per_patch.Resolved(1, f), big) << f;
    EXPECT_FALSE(median_only.Resolved(1, f));
    EXPECT_TRUE(per_patch.Resolved(0, f / 4));
    resolved += big;
  }
  EXPECT_GT(resolved, 0);
  EXPECT_LT(resolved, scene.hierarchy.FaceCount(1));
}

TEST(PatchLevels, RefinementGoesDeeperOnlyWhereThePatchesStillCoverTheArea) {
  const auto& refinement = Scene();
  const auto& scene = refinement.scene;
  const PatchLevels probe(scene.hierarchy, scene.control, scene.cameras, 1.0, true);
  StereoRefinementOptions options;
  options.min_patch_area = AreaBetweenMedianAndLargest(probe);
  options.adaptive_threshold = 0.0;  // every patch "moved": the resolution rule alone decides
  options.detail_threshold = 0.0;    // (the large-detail rule off: tested below)
  options.solver.max_iterations = 2;
  const geometry::Positions perturbed = testing::Perturbed(scene.hierarchy, scene.control, 0.5e-3);
  const RefinementResult deeper = refinement.Refine(perturbed, 1, options);
  ASSERT_EQ(deeper.levels.size(), 2u);
  EXPECT_GT(deeper.levels[1].active_fraction, 0.0);
  EXPECT_LT(deeper.levels[1].active_fraction, 1.0);
  options.per_patch_levels = false;
  const RefinementResult median = refinement.Refine(perturbed, 1, options);
  EXPECT_EQ(median.levels.size(), 1u);
  std::cout << "[ figures  ] level 1 refined on " << 100 * deeper.levels[1].active_fraction
            << " % of the patches\n";
}

TEST(PatchLevels, PatchesBelowTheAreaFloorAreResolvedForLargeDetailsDownToTheDetailFloor) {
  const auto& scene = Scene().scene;
  const PatchLevels probe(scene.hierarchy, scene.control, scene.cameras, 1.0, true);
  std::vector<double> areas = probe.base_areas();
  std::sort(areas.begin(), areas.end());
  const double largest = areas.back();
  // No level-1 patch covers the area floor; those of the larger half of the base faces
  // cover the detail floor.
  const double floor = 1.01 * largest, detail_floor = 0.25 * areas[areas.size() / 2];
  const PatchLevels levels(scene.hierarchy, scene.control, scene.cameras, floor, true, detail_floor);
  const PatchLevels without(scene.hierarchy, scene.control, scene.cameras, floor, true);
  EXPECT_EQ(levels.median_level(), 0);
  EXPECT_GE(levels.finest_level(), 1);
  EXPECT_EQ(without.finest_level(), 0);
  int for_detail = 0;
  for (int f = 0; f < scene.hierarchy.FaceCount(1); ++f) {
    EXPECT_FALSE(levels.Resolved(1, f)) << f;
    EXPECT_FALSE(without.ResolvedForDetail(1, f)) << f;
    const bool big = levels.base_areas()[f / 4] / 4.0 >= detail_floor;
    EXPECT_EQ(levels.ResolvedForDetail(1, f), big) << f;
    for_detail += big;
  }
  EXPECT_GT(for_detail, 0);
  EXPECT_LT(for_detail, scene.hierarchy.FaceCount(1));
}

// A smooth dent of the level-1 details around the direction `towards` (zero beyond ~50°):
// a local feature the base level cannot follow.
geometry::Positions Dented(const geometry::LoopHierarchy& hierarchy, const geometry::Positions& control,
                           double depth, const Eigen::Vector3d& towards) {
  geometry::MultiresShape shape = geometry::MultiresShape::Analyze(hierarchy, control);
  geometry::Positions& d1 = shape.Detail(1);
  const geometry::Positions c1 = shape.Synthesize(hierarchy, 1);
  for (Eigen::Index v = 0; v < d1.rows(); ++v) {
    const double cosine = c1.row(v).normalized().dot(towards.normalized());
    d1(v, 0) -= depth * std::pow(std::max(0.0, (cosine - 0.65) / 0.35), 2);
  }
  return shape.Synthesize(hierarchy, hierarchy.finest_level());
}

// RMS distance to the true surface of the limit points of `control` within ~45° of
// `towards` (the dent of Dented).
double RmsNear(const testing::RefinementScene& refinement, const geometry::Positions& control,
               const Eigen::Vector3d& towards) {
  const geometry::ClosestPointTree tree({refinement.limit * refinement.scene.control, refinement.tessellation.faces},
                                        "truth");
  const geometry::Positions points = refinement.limit * control;
  double sum = 0.0;
  int count = 0;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d p = points.row(i).transpose();
    if (p.normalized().dot(towards.normalized()) < 0.7) continue;
    sum += (tree.Closest(p).point - p).squaredNorm();
    ++count;
  }
  EXPECT_GT(count, 0);
  return std::sqrt(sum / std::max(count, 1));
}

TEST(PatchLevels, LargeDetailsAreRefinedBelowTheAreaFloorOnlyWhereTheyAre) {
  const auto& refinement = Scene();
  const auto& scene = refinement.scene;
  const PatchLevels probe(scene.hierarchy, scene.control, scene.cameras, 1.0, true);
  std::vector<double> areas = probe.base_areas();
  std::sort(areas.begin(), areas.end());
  StereoRefinementOptions options;
  options.min_patch_area = 1.01 * areas.back();           // no level-1 patch by the area rule
  options.min_detail_patch_area = 1.01 * areas.back() / 16;  // level 1 only
  options.adaptive_threshold = 0.0;
  options.detail_threshold = 0.01;
  options.solver.max_iterations = 4;
  // The rim term acts along the outlines wherever a level is refined, which level 1
  // everywhere reaches and the dent's level 1 does not; it has its own tests
  // (stereo_refinement_test.cpp). Off, so that the dent alone is compared (with it: level
  // 0 only 0.132 mm, the dent's level 1 0.081 mm, level 1 everywhere 0.074 mm).
  options.rim_band = 0.0;
  // A 3 mm dent facing the cameras (the potato's radius is 0.1, the base edges ~0.03).
  const Eigen::Vector3d towards(0.3, -1.0, 0.6);
  const geometry::Positions dented = Dented(scene.hierarchy, scene.control, 3e-3, towards);
  const RefinementResult with = refinement.Refine(dented, 1, options);
  options.detail_threshold = 0.0;
  const RefinementResult without = refinement.Refine(dented, 1, options);
  ASSERT_EQ(without.levels.size(), 1u);
  options.finest_level = 1;  // level 1 everywhere: the reference
  const RefinementResult everywhere = refinement.Refine(dented, 1, options);
  ASSERT_GE(with.levels.size(), 2u);
  // Level 1 is refined around the dent, not everywhere …
  EXPECT_GT(with.levels[1].active_fraction, 0.0);
  EXPECT_LT(with.levels[1].active_fraction, 0.5);
  // … and it follows the dent that level 0 could not.
  const double start = RmsNear(refinement, dented, towards);
  const double rms_with = RmsNear(refinement, with.control[0], towards);
  const double rms_without = RmsNear(refinement, without.control[0], towards);
  EXPECT_LT(rms_without, start);
  const double rms_everywhere = RmsNear(refinement, everywhere.control[0], towards);
  EXPECT_LT(rms_with, 0.9 * rms_without);
  EXPECT_LT(rms_with, 1.05 * rms_everywhere);
  std::cout << "[ figures  ] RMS to the truth near the dent: dented " << 1e3 * start << " mm, level 0 only "
            << 1e3 * rms_without << " mm, with the large-detail level 1 (" << 100 * with.levels[1].active_fraction
            << " % of its patches) " << 1e3 * rms_with << " mm, level 1 everywhere " << 1e3 * rms_everywhere
            << " mm\n";
}

}  // namespace
}  // namespace subflow::solver
