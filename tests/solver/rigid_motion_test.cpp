// The rigid / non-rigid split of method §5: the least-squares fit of ∂c⁰/∂t = v + ω × c⁰,
// exact on rigid velocity fields, exact for finite rotations in the Cayley / midpoint
// convention, and a non-rigid flow and motion energy that vanish for rigid sequences and
// concentrate where a deformation is.
#include "solver/rigid/rigid_motion.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/icosphere.h"

namespace subflow::solver {
namespace {

using geometry::Positions;

Positions RandomPoints(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Positions p(count, 3);
  for (int i = 0; i < count; ++i)
    for (int d = 0; d < 3; ++d) p(i, d) = 0.1 * uniform(rng) + (d == 0 ? 2.0 : 0.0);
  return p;
}

// Exact on an instantaneous rigid field: v, ω recovered to rounding (1e-10 relative to
// |v|, |ω| ≈ 1e-3..1e-2; the 3×3 normal equations are well conditioned about the centroid,
// even with the points 2 units away from the origin).
TEST(RigidMotion, FitRecoversVelocityAndAngularVelocityExactly) {
  const Positions p = RandomPoints(200, 1);
  RigidMotion truth;
  truth.v = Eigen::Vector3d(1.3e-3, -0.6e-3, 0.5e-3);
  truth.omega = Eigen::Vector3d(0.01, -0.02, 0.015);
  const Positions dc = truth.Velocity(p);
  const RigidMotion fitted = FitRigidMotion(p, dc);
  EXPECT_LT((fitted.v - truth.v).norm(), 1e-10);
  EXPECT_LT((fitted.omega - truth.omega).norm(), 1e-10);
  EXPECT_LT(fitted.rms_residual, 1e-12);
  // The non-rigid flow of a rigid field is zero (to rounding).
  EXPECT_LT(NonRigidFlow(p, dc, fitted).cwiseAbs().maxCoeff(), 1e-12);
}

// A finite rotation of 5° (far beyond the first-order regime, where x' − x − ω × x is off
// by ~|ω|²/2 ≈ 4e-3 relative) is recovered exactly from midpoints: x' − x = w × (x + x')/2.
TEST(RigidMotion, MidpointFitIsExactForFiniteRotations) {
  const Positions p = RandomPoints(100, 2);
  const double angle = 5.0 * M_PI / 180.0;
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  const Eigen::Vector3d t(0.002, 0.001, -0.003);
  Positions moved(p.rows(), 3);
  for (int i = 0; i < p.rows(); ++i) moved.row(i) = (R * p.row(i).transpose() + t).transpose();
  const RigidMotion fitted = FitRigidMotion(0.5 * (p + moved), moved - p);
  EXPECT_NEAR(fitted.RotationAngle(), angle, 1e-12);
  EXPECT_LT((fitted.omega.normalized() - axis).norm(), 1e-10);
  EXPECT_LT(fitted.rms_residual, 1e-13);
  // With start positions instead of midpoints the fit is only first-order: it is off.
  const RigidMotion first_order = FitRigidMotion(p, moved - p);
  EXPECT_GT(std::abs(first_order.RotationAngle() - angle), 1e-5);
}

TEST(RigidMotion, AnalyzeFlowOfARigidSequenceHasNoNonRigidPart) {
  const geometry::TriangleMesh sphere = geometry::MakeIcosphere(2, 0.1);
  std::vector<Positions> frames = {sphere.V};
  for (int f = 1; f < 4; ++f) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.03 * f, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Positions moved(sphere.V.rows(), 3);
    for (int i = 0; i < moved.rows(); ++i)
      moved.row(i) = (R * sphere.V.row(i).transpose() + Eigen::Vector3d(0.001 * f, 0, 0)).transpose();
    frames.push_back(moved);
  }
  const std::vector<RigidMotion> rigid = FitRigidMotions(frames);
  ASSERT_EQ(rigid.size(), 3u);
  for (const RigidMotion& motion : rigid) EXPECT_NEAR(motion.RotationAngle(), 0.03, 1e-12);
  const FlowAnalysis analysis = AnalyzeFlow(frames, rigid);
  ASSERT_EQ(analysis.flow.size(), 4u);
  EXPECT_LT(analysis.non_rigid_energy.maxCoeff(), 1e-13);
  EXPECT_GT(analysis.motion_energy.minCoeff(), 0.0);
  // Motion energy = Σ_f |flow_f| per vertex; the last frame's flow is zero.
  EXPECT_NEAR(analysis.motion_energy(0),
              analysis.flow[0].row(0).norm() + analysis.flow[1].row(0).norm() +
                  analysis.flow[2].row(0).norm(),
              1e-15);
  EXPECT_EQ(analysis.flow[3].cwiseAbs().maxCoeff(), 0.0);
}

// A bump that grows on one cap (z > 0.08, ~10 % of the vertices) of a translating sphere:
// the mean non-rigid energy per vertex on the cap is more than 5× the mean elsewhere (the
// least-squares rigid fit absorbs the bump's mean motion, ≈ 0.09 mm/frame along z, which
// then shows up as non-rigid flow everywhere else; measured ratio ≈ 10).
TEST(RigidMotion, NonRigidEnergyConcentratesWhereTheDeformationIs) {
  const geometry::TriangleMesh sphere = geometry::MakeIcosphere(3, 0.1);
  std::vector<Positions> frames;
  for (int f = 0; f < 3; ++f) {
    Positions x = sphere.V;
    for (int i = 0; i < x.rows(); ++i) {
      const double z = sphere.V(i, 2) / 0.1;
      const double bump = z > 0.8 ? 0.002 * f * (z - 0.8) / 0.2 : 0.0;
      x.row(i) += bump * sphere.V.row(i) / 0.1 + Eigen::RowVector3d(0.001 * f, 0, 0);
    }
    frames.push_back(x);
  }
  const FlowAnalysis analysis = AnalyzeFlow(frames, FitRigidMotions(frames));
  double inside = 0.0, outside = 0.0;
  int inside_count = 0;
  for (int i = 0; i < sphere.V.rows(); ++i) {
    if (sphere.V(i, 2) > 0.08) {
      inside += analysis.non_rigid_energy(i);
      ++inside_count;
    } else {
      outside += analysis.non_rigid_energy(i);
    }
  }
  const double inside_mean = inside / inside_count;
  const double outside_mean = outside / (sphere.V.rows() - inside_count);
  EXPECT_GT(inside_mean, 5.0 * outside_mean);
  // The translation is recovered in full; the bump adds only to v_z.
  for (const RigidMotion& motion : FitRigidMotions(frames)) EXPECT_NEAR(motion.v.x(), 0.001, 1e-12);
}

TEST(RigidMotion, CollinearPointsAreRejected) {
  Positions p(4, 3);
  p << 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3;
  EXPECT_THROW(FitRigidMotion(p, Positions::Zero(4, 3)), Error);
  EXPECT_THROW(FitRigidMotion(p, Positions::Zero(3, 3)), Error);
  EXPECT_THROW(FitRigidMotion(p.topRows(2), Positions::Zero(2, 3)), Error);
}

}  // namespace
}  // namespace subflow::solver
