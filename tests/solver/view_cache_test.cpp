// The view cache of the refinement (solver/stereo/view_cache.h): correlation blocks that
// read views sampled once per evaluation point give exactly the residuals and Jacobians of
// blocks that sample their own, follow the parameters from one point to the next, and
// share each view among the stereo and temporal blocks that compare it.
#include <cstdio>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "solver/stereo/photometric_residuals.h"
#include "solver/stereo/view_cache.h"
#include "tests/solver/refinement_test_scene.h"

namespace subflow::solver {
namespace {

using testing::OpenedWindow;
using testing::Scene;

// The stereo and temporal blocks of every patch at every solved frame of the window.
struct Blocks {
  std::vector<std::unique_ptr<PatchCorrelationCost>> costs;
  std::vector<std::vector<double*>> parameters;
};

Blocks BuildBlocks(RefinementWindow& window) {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(options);
  Blocks blocks;
  for (int t = window.first; t <= window.last; ++t)
    for (int f = 0; f < static_cast<int>(window.active_faces.size()); ++f) {
      const PatchCameras seen = CamerasOfPatch(window, t, f);
      AddStereoResidual(window, t, f, seen, nullptr, &problem);
      AddTemporalResiduals(window, t, f, seen, nullptr, &problem);
    }
  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  for (ceres::ResidualBlockId id : ids) {
    const auto* cost = dynamic_cast<const PatchCorrelationCost*>(problem.GetCostFunctionForResidualBlock(id));
    blocks.costs.emplace_back(const_cast<PatchCorrelationCost*>(cost));
    blocks.parameters.emplace_back();
    problem.GetParameterBlocksForResidualBlock(id, &blocks.parameters.back());
  }
  return blocks;
}

// Residuals and Jacobians of block i at the current parameters.
void EvaluateBlock(const Blocks& blocks, std::size_t i, std::vector<double>* residuals,
                   std::vector<std::vector<double>>* jacobians) {
  const PatchCorrelationCost& cost = *blocks.costs[i];
  residuals->assign(cost.num_residuals(), 0.0);
  jacobians->assign(cost.parameter_block_sizes().size(), {});
  std::vector<double*> pointers;
  for (std::size_t b = 0; b < jacobians->size(); ++b) {
    (*jacobians)[b].assign(static_cast<std::size_t>(cost.num_residuals()) * cost.parameter_block_sizes()[b], 0.0);
    pointers.push_back((*jacobians)[b].data());
  }
  ASSERT_TRUE(cost.Evaluate(blocks.parameters[i].data(), residuals->data(), pointers.data()));
}

void SetIncrements(RefinementWindow& window, std::mt19937* random, double amplitude) {
  std::uniform_real_distribution<double> uniform(-amplitude, amplitude);
  for (auto& [frame, state] : window.states)
    for (double& e : state.increments) e = uniform(*random);
}

// Three frames at level 1, dof 3 and dof 1: every block's residuals and Jacobians through
// the cache equal, to the bit, those of the same block sampling its own views — at a
// first point and again after the parameters moved (a stale cache fails the second).
TEST(ViewCache, BlocksReadExactlyWhatTheyWouldSampleThemselvesAtEveryPoint) {
  for (int dof : {3, 1}) {
    StereoRefinementOptions options;
    options.normal_only_from_level = dof == 3 ? 2 : 0;
    OpenedWindow own(Scene(), Scene().scene.control, 3, 1, 0, 2, options);
    OpenedWindow cached(Scene(), Scene().scene.control, 3, 1, 0, 2, options);
    ASSERT_EQ(cached.window.dof, dof);
    ViewCache cache(0, static_cast<int>(cached.window.states.size()), static_cast<int>(cached.window.cameras->size()),
                    static_cast<int>(cached.window.active_faces.size()), dof);
    cached.window.views = &cache;
    const Blocks reference = BuildBlocks(own.window);
    const Blocks shared = BuildBlocks(cached.window);
    ASSERT_EQ(reference.costs.size(), shared.costs.size());
    ASSERT_GT(shared.costs.size(), 100u);
    ASSERT_GT(cache.size(), 0);  // the blocks read the cache

    std::mt19937 random_own(3), random_cached(3);
    for (int point = 0; point < 2; ++point) {
      SetIncrements(own.window, &random_own, 0.001);
      SetIncrements(cached.window, &random_cached, 0.001);
      cache.PrepareForEvaluation(true, true);
      for (std::size_t i = 0; i < shared.costs.size(); ++i) {
        std::vector<double> r_own, r_cached;
        std::vector<std::vector<double>> j_own, j_cached;
        EvaluateBlock(reference, i, &r_own, &j_own);
        EvaluateBlock(shared, i, &r_cached, &j_cached);
        ASSERT_EQ(r_own, r_cached) << "dof " << dof << ", point " << point << ", block " << i;
        ASSERT_EQ(j_own, j_cached) << "dof " << dof << ", point " << point << ", block " << i;
      }
    }
  }
}

// Each view is sampled once however many blocks compare it: over a 3-frame window the
// stereo block and the temporal blocks of a patch share their cameras' views, so the
// blocks compare about three times as many views as the cache holds.
TEST(ViewCache, SharesEachViewAmongTheBlocksThatCompareIt) {
  OpenedWindow opened(Scene(), Scene().scene.control, 3, 1, 0, 2);
  ViewCache cache(0, static_cast<int>(opened.window.states.size()), static_cast<int>(opened.window.cameras->size()),
                  static_cast<int>(opened.window.active_faces.size()), opened.window.dof);
  opened.window.views = &cache;
  const Blocks blocks = BuildBlocks(opened.window);
  int compared = 0;
  for (const auto& cost : blocks.costs) {
    std::vector<char> used(16, 0);
    for (const CorrelationPair& pair : cost->pairs()) used[pair.a] = used[pair.b] = 1;
    for (char u : used) compared += u;
  }
  std::printf("%d views compared by %zu blocks, %d sampled\n", compared, blocks.costs.size(), cache.size());
  EXPECT_GT(compared, 2 * cache.size());
}

TEST(ViewCache, RejectsViewsOutsideIt) {
  OpenedWindow opened(Scene(), Scene().scene.control, 1, 0, 0, 0);
  ViewCache cache(0, 1, 2, 3, 1);
  const PatchStencil& stencil = opened.window.sampling->stencil[0];
  auto no_view = [] { return PatchView{}; };
  EXPECT_THROW(cache.Add(1, 0, 0, stencil, no_view, {}, {}), Error);
  EXPECT_THROW(cache.Add(0, 2, 0, stencil, no_view, {}, {}), Error);
  EXPECT_THROW(cache.Add(0, 0, 3, stencil, no_view, {}, {}), Error);
  EXPECT_THROW(cache.Add(0, 0, 0, stencil, no_view, {}, {}), Error);  // no image, camera, positions
  EXPECT_THROW(ViewCache(0, 1, 1, 1, 2), Error);
}

}  // namespace
}  // namespace subflow::solver
