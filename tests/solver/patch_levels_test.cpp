#include "solver/stereo/patch_levels.h"

#include <algorithm>
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

}  // namespace
}  // namespace subflow::solver
