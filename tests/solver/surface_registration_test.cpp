#include "solver/shape/surface_registration.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/closest_point.h"
#include "geometry/icosphere.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/mean_edge_length.h"
#include "solver/motion/motion_init.h"
#include "solver/shape/hierarchy_fit.h"

namespace subflow::solver {
namespace {

using geometry::Positions;

constexpr double kPi = 3.14159265358979323846;

// An elongated ellipsoid (half-axes 3, 1, 1): a limb from x = −3 to x = 3.
geometry::TriangleMesh Limb(int subdivisions) {
  geometry::TriangleMesh mesh = geometry::MakeIcosphere(subdivisions, 1.0);
  mesh.V.col(0) *= 3.0;
  return mesh;
}

// The limb bent at its middle: the half x > 0 turned by `degrees` about the z axis through
// the origin (a knee), the half x ≤ 0 left where it is.
geometry::TriangleMesh Bent(geometry::TriangleMesh mesh, double degrees) {
  const double a = degrees * kPi / 180.0;
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    const double x = mesh.V(v, 0), y = mesh.V(v, 1);
    if (x <= 0.0) continue;
    mesh.V(v, 0) = std::cos(a) * x - std::sin(a) * y;
    mesh.V(v, 1) = std::sin(a) * x + std::cos(a) * y;
  }
  return mesh;
}

// Mean distance from the target's vertices to the finest limit surface of `levels`: how
// much of the target the fitted surface leaves uncovered.
double TargetToSurface(const geometry::LoopHierarchy& hierarchy, const std::vector<Positions>& levels,
                       const geometry::TriangleMesh& target) {
  const int finest = hierarchy.finest_level();
  const geometry::TriangleMesh surface{hierarchy.LimitPositions(finest) * levels.back(),
                                       hierarchy.LevelFaces(finest)};
  return geometry::ClosestPointTree(surface).Distances(target.V).mean();
}

struct BentLimb {
  geometry::TriangleMesh base = Limb(2);
  geometry::LoopHierarchy hierarchy{base.F, base.vertex_count(), 2};
  geometry::TriangleMesh straight = Limb(5);
  geometry::TriangleMesh bent = Bent(Limb(5), 35.0);
  // The hierarchy fitted to the straight limb, level by level.
  std::vector<Positions> straight_fit =
      FitHierarchyToSurface(hierarchy, base.V, geometry::ClosestPointTree(straight), HierarchyFitOptions());
  // Its base: the previous frame's surface.
  Positions fitted_base = straight_fit.front();
  // Its finest control points (with their details): a tracked surface.
  Positions tracked = straight_fit.back();
  // Motion initialization's default reach of the correction: 3 mean finest edges.
  double max_correction = 3.0 * geometry::MeanEdgeLength(hierarchy.Topology(hierarchy.finest_level()), tracked);
};

// A limb turned by 35° at its knee: snapping the previous frame's surface along its normals
// cannot follow (the normal lines at the turned half miss the target or land on its side);
// registering it first moves the surface onto the turned half.
TEST(SurfaceRegistration, FollowsALimbTurnedAtItsKneeWhereSnappingAloneCannot) {
  const BentLimb limb;
  const geometry::ClosestPointTree target(limb.bent, "bent limb");

  const std::vector<Positions> snapped =
      FitHierarchyToSurface(limb.hierarchy, limb.fitted_base, target, HierarchyFitOptions());
  SurfaceRegistrationReport report;
  const Positions registered =
      RegisterToSurface(limb.hierarchy, limb.fitted_base, target, SurfaceRegistrationOptions(), &report);
  const std::vector<Positions> fitted =
      FitHierarchyToSurface(limb.hierarchy, registered, target, HierarchyFitOptions());

  const double without = TargetToSurface(limb.hierarchy, snapped, limb.bent);
  const double with = TargetToSurface(limb.hierarchy, fitted, limb.bent);
  EXPECT_TRUE(report.applied);
  EXPECT_LT(report.mean_target_distance_after, 0.5 * report.mean_target_distance_before);
  // The limb's radius is 1: within 2 % of it with the registration, and at least 3×
  // better than without.
  EXPECT_LT(with, 0.02) << "without registration " << without;
  EXPECT_LT(3.0 * with, without) << "with " << with;
}

// A surface already on its target is not registered (the gate), and left there.
TEST(SurfaceRegistration, LeavesASurfaceOnItsTargetAlone) {
  const BentLimb limb;
  const geometry::ClosestPointTree target(limb.straight, "limb");
  SurfaceRegistrationReport report;
  const Positions registered =
      RegisterToSurface(limb.hierarchy, limb.fitted_base, target, SurfaceRegistrationOptions(), &report);
  EXPECT_FALSE(report.applied);
  EXPECT_EQ(registered, limb.fitted_base);
  EXPECT_LT(report.mean_target_distance_before, 0.25 * 0.1);  // well inside the gate
}

// Without the gate, a surface already on its target stays there: the registration neither
// drifts nor shrinks it.
TEST(SurfaceRegistration, KeepsASurfaceOnItsTargetInPlaceWithoutTheGate) {
  const BentLimb limb;
  const geometry::ClosestPointTree target(limb.straight, "limb");
  SurfaceRegistrationOptions options;
  options.min_start_distance_edges = 0.0;
  SurfaceRegistrationReport report;
  const Positions registered = RegisterToSurface(limb.hierarchy, limb.fitted_base, target, options, &report);
  EXPECT_TRUE(report.applied);
  const Eigen::VectorXd moves = (registered - limb.fitted_base).rowwise().norm();
  // The limb's radius is 1. The control points move by under 1 % of it on average and 3 %
  // at most (most of it along the surface: the level-1 limit mesh's chords sag, and the
  // target-to-surface term pulls them out a little), and the limit surface stays within
  // 0.5 % of the target (the snapping that follows the registration removes that).
  EXPECT_LT(moves.mean(), 0.01);
  EXPECT_LT(moves.maxCoeff(), 0.03);
  EXPECT_LT(report.mean_surface_distance_after, 0.005);
  EXPECT_LT(report.mean_target_distance_after, 0.005);
}

TEST(SurfaceRegistration, DisabledReturnsTheStartAndStillMeasures) {
  const BentLimb limb;
  const geometry::ClosestPointTree target(limb.bent, "bent limb");
  SurfaceRegistrationOptions options;
  options.enabled = false;
  SurfaceRegistrationReport report;
  const Positions registered = RegisterToSurface(limb.hierarchy, limb.fitted_base, target, options, &report);
  EXPECT_EQ(registered, limb.fitted_base);
  EXPECT_FALSE(report.applied);
  EXPECT_GT(report.mean_target_distance_before, 0.0);
  EXPECT_EQ(report.mean_target_distance_after, report.mean_target_distance_before);
}

TEST(SurfaceRegistration, RejectsBadInputAndOptions) {
  const BentLimb limb;
  const geometry::ClosestPointTree target(limb.bent, "bent limb");
  EXPECT_THROW(RegisterToSurface(limb.hierarchy, Positions::Zero(5, 3), target, SurfaceRegistrationOptions()),
               Error);
  Positions with_nan = limb.fitted_base;
  with_nan(0, 0) = std::nan("");
  EXPECT_THROW(RegisterToSurface(limb.hierarchy, with_nan, target, SurfaceRegistrationOptions()), Error);
  SurfaceRegistrationOptions options;
  options.stiffness_end = 0.0;
  EXPECT_THROW(options.Check(), Error);
  options = SurfaceRegistrationOptions();
  options.max_distance_edges = -1.0;
  EXPECT_THROW(options.Check(), Error);
  options = SurfaceRegistrationOptions();
  options.min_start_distance_edges = -1.0;
  EXPECT_THROW(options.Check(), Error);
  options = SurfaceRegistrationOptions();
  options.min_normal_cosine = 2.0;
  EXPECT_THROW(options.Check(), Error);
}

// Motion initialization's correction of a tracked surface towards its frame's fit
// (CorrectTowardsFit): the surface is the straight limb's (its finest control points, with
// their details), the fit is the limb turned by 35° at its knee, as after a chain of steps
// whose image motion lost a fast limb. The snap along the normals alone (bounded by 3 mean
// finest edges) leaves the turned half off; the registration before it brings it on.
TEST(SurfaceRegistration, MotionCorrectionBringsADriftedLimbBackOntoItsFit) {
  const BentLimb limb;
  const Positions& tracked = limb.tracked;
  const geometry::ClosestPointTree fit(limb.bent, "bent limb");
  const double max_correction = limb.max_correction;
  const auto correct = [&](bool registration_enabled, MotionFrameReport* report) {
    MotionInitOptions options;
    options.registration.enabled = registration_enabled;
    const SurfaceRegistration registration(limb.hierarchy, options.registration);
    return CorrectTowardsFit(limb.hierarchy, registration, tracked, fit, options, max_correction, report);
  };
  MotionFrameReport with_report, without_report;
  const double with = TargetToSurface(limb.hierarchy, {correct(true, &with_report)}, limb.bent);
  const double without = TargetToSurface(limb.hierarchy, {correct(false, &without_report)}, limb.bent);
  EXPECT_TRUE(with_report.registration.applied);
  EXPECT_FALSE(without_report.registration.applied);
  EXPECT_TRUE(with_report.corrected && without_report.corrected);
  // The limb's radius is 1. (The snap blends half-way, hull_weight 0.5: neither lands on the fit.)
  EXPECT_LT(with, 0.5 * without) << "with registration " << with << ", snap alone " << without;
  std::printf("[ figures ] bent limb -> corrected surface, mean distance (of the radius): %.4f with "
              "registration, %.4f snap alone\n",
              with, without);

  // A surface on its fit: the gate leaves it to the snap, exactly as without registration.
  const geometry::ClosestPointTree straight(limb.straight, "straight limb");
  MotionInitOptions options;
  options.registration.enabled = true;
  const SurfaceRegistration registration(limb.hierarchy, options.registration);
  MotionFrameReport on_report, off_report;
  const Positions on = CorrectTowardsFit(limb.hierarchy, registration, tracked, straight, options, max_correction,
                                         &on_report);
  options.registration.enabled = false;
  const Positions off = CorrectTowardsFit(limb.hierarchy, registration, tracked, straight, options,
                                          max_correction, &off_report);
  EXPECT_FALSE(on_report.registration.applied);
  EXPECT_EQ((on - off).cwiseAbs().maxCoeff(), 0.0);
}

// The retrack's gate (registration_min_unreached): a frame is registered only when more than
// that fraction of its surface is out of the snap's reach of its fit. The bent limb leaves
// 0.29 of the straight limb's surface out of reach (next test): a quarter lets the
// registration run as without the gate (the same result, to the bit), a half keeps it off
// (the snap alone).
TEST(SurfaceRegistration, ARegistrationGatedOnTheSurfaceOutOfReach) {
  const BentLimb limb;
  const geometry::ClosestPointTree fit(limb.bent, "bent limb");
  MotionInitOptions options;
  options.registration.enabled = true;
  const SurfaceRegistration registration(limb.hierarchy, options.registration);
  const auto correct = [&](double min_unreached, MotionFrameReport* report, Positions* shift) {
    MotionInitOptions gated = options;
    gated.registration_min_unreached = min_unreached;
    return CorrectTowardsFit(limb.hierarchy, registration, limb.tracked, fit, gated, limb.max_correction, report,
                             shift);
  };
  MotionFrameReport ungated_report, quarter_report, half_report;
  Positions quarter_shift, half_shift;
  const Positions ungated = correct(0.0, &ungated_report, nullptr);
  const Positions quarter = correct(0.25, &quarter_report, &quarter_shift);
  const Positions half = correct(0.5, &half_report, &half_shift);
  EXPECT_TRUE(ungated_report.registration.applied);
  EXPECT_TRUE(quarter_report.registration.applied);
  EXPECT_EQ((quarter - ungated).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_FALSE(half_report.registration.applied);
  // The registration's displacement is handed out when registered, and only then.
  ASSERT_EQ(quarter_shift.rows(), limb.tracked.rows());
  EXPECT_GT(quarter_shift.rowwise().norm().maxCoeff(), 0.1);  // the turned half moves (radius 1)
  EXPECT_EQ(half_shift.rows(), 0);
  options.registration.enabled = false;
  MotionFrameReport snap_report;
  const Positions snap_only =
      CorrectTowardsFit(limb.hierarchy, registration, limb.tracked, fit, options, limb.max_correction, &snap_report);
  EXPECT_EQ((half - snap_only).cwiseAbs().maxCoeff(), 0.0);

  options.registration_min_unreached = 1.0;  // a fraction below 1
  EXPECT_THROW(options.Check(), Error);
}

// What the correction could not reach is reported (MotionFrameReport::correction_unreached):
// of the straight limb's surface against the limb bent 35° at its knee, the part beyond the
// knee that turned away (0.29 of the surface) has no fit within the snap's reach; against
// the straight limb, all of it has.
// MotionInitResult::FramesOffTarget lists the frames above a fraction, in order.
TEST(SurfaceRegistration, MotionCorrectionReportsTheSurfaceOutOfItsReach) {
  const BentLimb limb;
  const Positions& tracked = limb.tracked;
  const double max_correction = limb.max_correction;
  MotionInitOptions options;
  const SurfaceRegistration registration(limb.hierarchy, options.registration);
  MotionInitResult result;
  result.frames.resize(3);
  for (int f = 0; f < 3; ++f) result.frames[f].frame = f;
  CorrectTowardsFit(limb.hierarchy, registration, tracked, geometry::ClosestPointTree(limb.bent, "bent limb"), options,
                    max_correction, &result.frames[2]);
  CorrectTowardsFit(limb.hierarchy, registration, tracked, geometry::ClosestPointTree(limb.straight, "straight limb"),
                    options, max_correction, &result.frames[1]);
  std::printf("[ figures ] out of reach: %.4f of the surface against the bent limb, %.4f against the straight\n",
              result.frames[2].correction_unreached, result.frames[1].correction_unreached);
  EXPECT_GT(result.frames[2].correction_unreached, 0.2);
  EXPECT_LT(result.frames[2].correction_unreached, 0.5);
  EXPECT_LT(result.frames[1].correction_unreached, 0.01);
  EXPECT_EQ(result.FramesOffTarget(0.2), std::vector<int>{2});
  EXPECT_TRUE(result.FramesOffTarget(0.9).empty());
  result.frames[0].correction_unreached = 1.0;  // not corrected (the reference frame): not listed
  EXPECT_EQ(result.FramesOffTarget(0.2), std::vector<int>{2});
}

}  // namespace
}  // namespace subflow::solver
