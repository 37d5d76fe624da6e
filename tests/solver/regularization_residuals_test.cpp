// The regularization residual families of the stereo refinement
// (solver/stereo/regularization_residuals.h) and the linear cost they are made of, each on
// a hand-built window over an icosphere: what each term penalizes, and what it leaves free.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/icosphere.h"
#include "solver/stereo/linear_residual_cost.h"
#include "solver/stereo/regularization_residuals.h"
#include "solver/stereo/stereo_refinement.h"

namespace subflow::solver {
namespace {

using geometry::Positions;

// Frames 0..frames−1 of an icosphere (base 42 vertices, one level) translating along x and
// growing (so that the details change over time);
// the window solves [first, last] of level `level` with identity bases (dof 3).
struct HandWindow {
  geometry::LoopHierarchy hierarchy;
  StereoRefinementOptions options;
  geometry::Trajectory trajectory;
  RefinementWindow window;

  HandWindow(int level, int frames, int first, int last)
      : hierarchy([] {
          const geometry::TriangleMesh base = geometry::MakeIcosphere(1, 1.0);
          return geometry::LoopHierarchy(base.F, base.vertex_count(), 1);
        }()) {
    options.normal_only_from_level = 99;
    const geometry::TriangleMesh base = geometry::MakeIcosphere(1, 1.0);
    std::vector<Positions> control;
    for (int t = 0; t < frames; ++t) {
      Positions c = hierarchy.Refine(base.V, 0, 1);
      c *= 1.0 + 0.05 * t * t;
      c.col(0).array() += 0.1 * t;
      control.push_back(c);
    }
    trajectory = geometry::AnalyzeTrajectory(hierarchy, control);
    window.options = &options;
    window.hierarchy = &hierarchy;
    window.trajectory = &trajectory;
    window.level = level;
    window.dof = 3;
    window.first = first;
    window.last = last;
    window.frame_count = frames;
    window.h = 0.5;
    const int vertices = hierarchy.VertexCount(level);
    window.active_faces.assign(hierarchy.FaceCount(level), 1);
    window.active_vertices.assign(vertices, 1);
    for (int t = std::max(0, first - 1); t <= std::min(frames - 1, last + 1); ++t) {
      FrameState state;
      state.level_control = trajectory[t].Synthesize(hierarchy, level);
      state.basis.assign(vertices, Eigen::Matrix3d::Identity());
      state.increments.assign(static_cast<std::size_t>(vertices) * 3, 0.0);
      window.states.emplace(t, std::move(state));
    }
  }
  void SetIncrement(int frame, int vertex, const Eigen::Vector3d& e) {
    Eigen::Map<Eigen::Vector3d>(window.Increment(frame, vertex)) = e;
  }
};

Eigen::VectorXd Residual(ceres::Problem& problem, ceres::ResidualBlockId id) {
  Eigen::VectorXd r(problem.GetCostFunctionForResidualBlock(id)->num_residuals());
  double cost = 0.0;
  problem.EvaluateResidualBlock(id, false, &cost, r.data(), nullptr);
  return r;
}

ceres::ResidualBlockId OnlyBlock(ceres::Problem& problem) {
  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  EXPECT_EQ(ids.size(), 1u);
  return ids.empty() ? nullptr : ids.front();
}

TEST(LinearResidualCost, IsTheAffineMapWithItsMatricesAsJacobians) {
  Eigen::MatrixXd A(2, 3), B(2, 1);
  A << 1, 2, 3, 4, 5, 6;
  B << -1, 0.5;
  const Eigen::Vector2d offset(0.25, -0.75);
  const LinearResidualCost cost({A, B}, offset);
  const double x[3] = {0.1, -0.2, 0.3}, y[1] = {2.0};
  const double* parameters[2] = {x, y};
  double r[2], jx[6], jy[2];
  double* jacobians[2] = {jx, jy};
  ASSERT_TRUE(cost.Evaluate(parameters, r, jacobians));
  const Eigen::Vector2d expected = A * Eigen::Vector3d(x) + B * y[0] + offset;
  EXPECT_DOUBLE_EQ(r[0], expected(0));
  EXPECT_DOUBLE_EQ(r[1], expected(1));
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 3; ++j) EXPECT_EQ(jx[3 * i + j], A(i, j));  // row-major
    EXPECT_EQ(jy[i], B(i, 0));
  }
  EXPECT_THROW(LinearResidualCost({A, Eigen::MatrixXd(3, 1)}), Error);
}

// w/h (e_v − mean of the ring): zero for a translation of the whole level, w/h e for a
// lone vertex's increment.
TEST(MembraneResidual, FreesTranslationsAndPenalizesABump) {
  HandWindow hand(0, 1, 0, 0);
  ceres::Problem problem;
  AddMembraneResidual(hand.window, 0, 5, &problem);
  const ceres::ResidualBlockId id = OnlyBlock(problem);
  const Eigen::Vector3d shift(0.01, -0.02, 0.03);
  for (int v = 0; v < hand.hierarchy.VertexCount(0); ++v) hand.SetIncrement(0, v, shift);
  EXPECT_LT(Residual(problem, id).norm(), 1e-15);
  for (int v = 0; v < hand.hierarchy.VertexCount(0); ++v) hand.SetIncrement(0, v, Eigen::Vector3d::Zero());
  hand.SetIncrement(0, 5, shift);
  const double w = hand.options.membrane_weight / hand.window.h;
  EXPECT_NEAR((Residual(problem, id) - w * shift).norm(), 0.0, 1e-15);
  hand.options.membrane_weight = 0.0;
  ceres::Problem none;
  AddMembraneResidual(hand.window, 0, 5, &none);
  EXPECT_EQ(none.NumResidualBlocks(), 0);
}

// Level 0: second differences of the increments only (a constant velocity and the rigid
// motion of the trajectories themselves are free). Above level 0: of the details d + e,
// with the current details' second difference as offset; none at the sequence's ends.
TEST(TemporalSmoothnessResidual, SecondDifferencesOfIncrementsAtLevelZeroAndOfDetailsAbove) {
  HandWindow base(0, 3, 1, 1);
  ceres::Problem problem;
  AddTemporalSmoothnessResidual(base.window, 1, 7, &problem);
  const ceres::ResidualBlockId id = OnlyBlock(problem);
  const Eigen::Vector3d step(0.01, 0.0, -0.01);
  for (int t = 0; t < 3; ++t) base.SetIncrement(t, 7, t * step);  // constant velocity
  EXPECT_LT(Residual(problem, id).norm(), 1e-15);
  base.SetIncrement(1, 7, 3.0 * step);
  const double w = base.options.temporal_smoothness / base.window.h;
  EXPECT_NEAR((Residual(problem, id) - w * (0.0 * step - 2.0 * 3.0 * step + 2.0 * step)).norm(), 0.0, 1e-15);
  ceres::Problem ends;
  AddTemporalSmoothnessResidual(base.window, 0, 7, &ends);
  AddTemporalSmoothnessResidual(base.window, 2, 7, &ends);
  EXPECT_EQ(ends.NumResidualBlocks(), 0);

  HandWindow detail(1, 3, 1, 1);
  ceres::Problem details;
  AddTemporalSmoothnessResidual(detail.window, 1, 50, &details);
  const auto d = [&](int t) { return Eigen::Vector3d(detail.trajectory[t].Detail(1).row(50).transpose()); };
  const Eigen::Vector3d offset = (detail.options.temporal_smoothness / detail.window.h) * (d(0) - 2.0 * d(1) + d(2));
  ASSERT_GT(offset.norm(), 1e-4);  // the details accelerate
  EXPECT_NEAR((Residual(details, OnlyBlock(details)) - offset).norm(), 0.0, 1e-15);
}

// The first difference of the tangential increments in frame t's tangent plane: a vertex
// that slides alike in both frames costs nothing, whatever it does along its normal; one
// that slides differently costs w/h times the difference. None at the sequence's last
// frame, and none for a vertex held to its normal in both frames.
TEST(SlideCoherenceResidual, FirstDifferencesOfTheSlidingInFrameTsTangentPlane) {
  HandWindow hand(0, 3, 1, 2);
  ceres::Problem problem;
  AddSlideCoherenceResidual(hand.window, 1, 7, &problem);
  const ceres::ResidualBlockId id = OnlyBlock(problem);
  ASSERT_NE(id, nullptr);
  hand.SetIncrement(1, 7, Eigen::Vector3d(0.03, 0.01, -0.02));
  hand.SetIncrement(2, 7, Eigen::Vector3d(-0.05, 0.01, -0.02));  // basis (n, t1, t2) = I
  EXPECT_LT(Residual(problem, id).norm(), 1e-15);
  hand.SetIncrement(2, 7, Eigen::Vector3d(-0.05, 0.04, -0.02));
  const double w = hand.options.slide_coherence / hand.window.h;
  EXPECT_NEAR((Residual(problem, id) - Eigen::Vector2d(-w * 0.03, 0.0)).norm(), 0.0, 1e-15);

  ceres::Problem last;
  AddSlideCoherenceResidual(hand.window, 2, 7, &last);
  EXPECT_EQ(last.NumResidualBlocks(), 0);

  hand.options.tangential_only_at_outlines = true;
  ceres::Problem held;
  AddSlideCoherenceResidual(hand.window, 1, 7, &held);
  EXPECT_EQ(held.NumResidualBlocks(), 0);
  hand.window.sliding.insert(hand.window.Increment(2, 7));
  AddSlideCoherenceResidual(hand.window, 1, 7, &held);
  EXPECT_EQ(held.NumResidualBlocks(), 1);
}

TEST(DampingResidual, IsProportionalToTheIncrement) {
  HandWindow hand(0, 1, 0, 0);
  ceres::Problem problem;
  AddDampingResidual(hand.window, 0, 3, &problem);
  const Eigen::Vector3d e(0.2, -0.1, 0.4);
  hand.SetIncrement(0, 3, e);
  EXPECT_NEAR((Residual(problem, OnlyBlock(problem)) - (hand.options.damping / hand.window.h) * e).norm(), 0.0,
              1e-15);
}

// Context frames and inactive vertices are constants; the others are bounded by
// max_step · h per component; the count is of free scalars.
TEST(BoundIncrements, FreesOnlyTheWindowsActiveVerticesWithinTheStepBound) {
  HandWindow hand(0, 3, 1, 1);
  hand.window.active_vertices[4] = 0;
  ceres::Problem problem;
  const int vertices = hand.hierarchy.VertexCount(0);
  for (int t = 0; t < 3; ++t)
    for (int v = 0; v < vertices; ++v) AddDampingResidual(hand.window, t, v, &problem);
  const int free = BoundIncrements(hand.window, {Eigen::Vector3d::Constant(-10), Eigen::Vector3d::Constant(10)},
                                   &problem);
  EXPECT_EQ(free, 3 * (vertices - 1));
  EXPECT_TRUE(problem.IsParameterBlockConstant(hand.window.Increment(0, 0)));
  EXPECT_TRUE(problem.IsParameterBlockConstant(hand.window.Increment(2, 0)));
  EXPECT_TRUE(problem.IsParameterBlockConstant(hand.window.Increment(1, 4)));
  EXPECT_FALSE(problem.IsParameterBlockConstant(hand.window.Increment(1, 0)));
  const double limit = hand.options.max_step * hand.window.h;
  EXPECT_EQ(problem.GetParameterLowerBound(hand.window.Increment(1, 0), 2), -limit);
  EXPECT_EQ(problem.GetParameterUpperBound(hand.window.Increment(1, 0), 0), limit);
}

// The normal-only increment keeps p + n e inside the box, and 0 is always allowed.
TEST(SlabRange, KeepsTheMovedPointInTheWorkingVolume) {
  const vision::Bounds box{Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1)};
  const auto [lo, hi] = SlabRange(Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(1, 0, 0), box);
  EXPECT_DOUBLE_EQ(lo, -1.5);
  EXPECT_DOUBLE_EQ(hi, 0.5);
  const Eigen::Vector3d diagonal = Eigen::Vector3d(1, 1, 0).normalized();
  const auto [dlo, dhi] = SlabRange(Eigen::Vector3d(0, 0.5, 0), diagonal, box);
  EXPECT_NEAR(dhi, 0.5 * std::sqrt(2.0), 1e-12);  // y reaches 1 first
  EXPECT_NEAR(dlo, -std::sqrt(2.0), 1e-12);       // x reaches −1 first
  const auto [olo, ohi] = SlabRange(Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(1, 0, 0), box);
  EXPECT_LE(olo, 0.0);  // already outside: may stay
  EXPECT_GE(ohi, 0.0);
}

}  // namespace
}  // namespace subflow::solver
