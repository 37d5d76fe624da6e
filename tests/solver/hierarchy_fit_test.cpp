#include "solver/shape/hierarchy_fit.h"

#include <cmath>

#include <gtest/gtest.h>

#include "geometry/closest_point.h"
#include "core/error.h"
#include "geometry/icosphere.h"
#include "geometry/loop_hierarchy.h"
#include "solver/shape/surface_snapping.h"

namespace subflow::solver {
namespace {

using geometry::Positions;

// Section 4.1, steps 2–4: a coarse icosahedron's limit surface lies well inside the sphere
// it is inscribed in (Loop surfaces shrink); fitting level by level must bring the limit
// surface of the finest level onto a finely tessellated sphere.
TEST(HierarchyFit, LimitSurfaceOfEveryLevelLandsOnTheTarget) {
  const geometry::TriangleMesh base = geometry::MakeIcosphere(0, 1.0);
  const geometry::TriangleMesh target_mesh = geometry::MakeIcosphere(5, 1.0);
  const geometry::ClosestPointTree target(target_mesh, "sphere");
  const geometry::LoopHierarchy hierarchy(base.F, base.vertex_count(), 3);

  const Positions unfitted_limit = hierarchy.LimitPositions(3) * hierarchy.Refine(base.V, 0, 3);
  const double unfitted_error = target.Distances(unfitted_limit).maxCoeff();

  std::vector<LevelFitSummary> summaries;
  const std::vector<Positions> levels =
      FitHierarchyToSurface(hierarchy, base.V, target, HierarchyFitOptions(), &summaries);
  ASSERT_EQ(levels.size(), 4u);
  ASSERT_EQ(summaries.size(), 4u);
  for (int level = 0; level <= 3; ++level) EXPECT_EQ(levels[level].rows(), hierarchy.VertexCount(level));

  const Positions fitted_limit = hierarchy.LimitPositions(3) * levels[3];
  const Eigen::VectorXd distances = target.Distances(fitted_limit);
  // The target is a polyhedral sphere (20·4⁵ faces, chord sag ≈ 1 − cos(0.03) ≈ 5e-4 of the
  // radius), so points exactly on it are all a target can ask; require the fit to be ten
  // times closer than the unfitted limit surface and within 1e-3 of the radius.
  EXPECT_LT(distances.maxCoeff(), 1e-3);
  EXPECT_LT(distances.maxCoeff(), 0.1 * unfitted_error);
  EXPECT_EQ(summaries.back().misses, 0);
  EXPECT_LE(summaries.back().mean_distance, summaries.front().max_distance + 1e-12);
}

TEST(HierarchyFit, RejectsBaseControlPointsOfTheWrongSize) {
  const geometry::TriangleMesh base = geometry::MakeIcosphere(0, 1.0);
  const geometry::ClosestPointTree target(geometry::MakeIcosphere(3, 1.0), "sphere");
  const geometry::LoopHierarchy hierarchy(base.F, base.vertex_count(), 1);
  EXPECT_THROW(FitHierarchyToSurface(hierarchy, Positions::Zero(5, 3), target, HierarchyFitOptions()),
               Error);
  Positions with_nan = base.V;
  with_nan(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(FitHierarchyToSurface(hierarchy, with_nan, target, HierarchyFitOptions()), Error);
}

// Motion initialization snaps every frame step without the extra cast that only measures
// the distance left (measure_after = false): the snapped points must be the same, and the
// applied correction must be reported exactly (and scale with the blend weight).
TEST(SurfaceSnapping, SkippingTheMeasurementAfterwardsChangesNothingButTheReport) {
  const geometry::TriangleMesh base = geometry::MakeIcosphere(1, 1.0);
  const geometry::ClosestPointTree target(geometry::MakeIcosphere(4, 1.2), "sphere");
  const geometry::LoopHierarchy hierarchy(base.F, base.vertex_count(), 1);
  const Positions control = hierarchy.Refine(base.V, 0, 1);
  SurfaceSnapOptions snap;
  snap.weight = 0.5;
  snap.iterations = 2;
  snap.max_distance = 1.0;
  SurfaceSnapReport measured, unmeasured;
  const Positions with = SnapToSurface(hierarchy, 1, control, target, snap, &measured);
  snap.measure_after = false;
  const Positions without = SnapToSurface(hierarchy, 1, control, target, snap, &unmeasured);
  EXPECT_EQ((with - without).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(measured.rms_distance_before, 0.15);  // the limit surface is inside the unit sphere
  EXPECT_LT(measured.rms_distance_after, 0.6 * measured.rms_distance_before);
  EXPECT_EQ(unmeasured.rms_distance_after, 0.0);
  EXPECT_EQ(unmeasured.rms_distance_before, measured.rms_distance_before);
  const double rms = std::sqrt((without - control).rowwise().squaredNorm().mean());
  EXPECT_NEAR(unmeasured.rms_correction, rms, 1e-12);
  snap.weight = 1.0;
  SurfaceSnapReport full;
  SnapToSurface(hierarchy, 1, control, target, snap, &full);
  EXPECT_NEAR(unmeasured.rms_correction, 0.5 * full.rms_correction, 1e-12);
}

}  // namespace
}  // namespace subflow::solver
