#include "solver/rigid/rigid_motion.h"

#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "core/error.h"

namespace subflow::solver {

using geometry::Positions;

Positions RigidMotion::Velocity(const Positions& x) const {
  Positions velocity(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const Eigen::Vector3d p = x.row(i).transpose();
    velocity.row(i) = (v + omega.cross(p)).transpose();
  }
  return velocity;
}

double RigidMotion::RotationAngle() const { return 2.0 * std::atan(omega.norm() / 2.0); }

RigidMotion FitRigidMotion(const Positions& p, const Positions& dc) {
  if (p.rows() != dc.rows())
    ThrowError("rigid motion fit", "velocities",
               std::to_string(dc.rows()) + " rows for " + std::to_string(p.rows()) + " points");
  if (p.rows() < 3)
    ThrowError("rigid motion fit", "points",
               "need at least 3 points, got " + std::to_string(p.rows()));
  if (!p.allFinite() || !dc.allFinite())
    ThrowError("rigid motion fit", "points", "positions and velocities must be finite");
  const Eigen::RowVector3d p_mean = p.colwise().mean();
  const Eigen::RowVector3d dc_mean = dc.colwise().mean();
  // Minimize Σ |e_i − ω × q_i|²: (Σ |q|² I − q qᵀ) ω = Σ q × e.
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    const Eigen::Vector3d q = (p.row(i) - p_mean).transpose();
    const Eigen::Vector3d e = (dc.row(i) - dc_mean).transpose();
    normal += q.squaredNorm() * Eigen::Matrix3d::Identity() - q * q.transpose();
    rhs += q.cross(e);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(normal);
  const double largest = eigen.eigenvalues().maxCoeff();
  if (!(largest > 0.0) || eigen.eigenvalues().minCoeff() <= 1e-12 * largest)
    ThrowError("rigid motion fit", "points",
               "the points are collinear (or coincide): the rotation is undetermined");
  RigidMotion motion;
  motion.omega = normal.ldlt().solve(rhs);
  motion.v = dc_mean.transpose() - motion.omega.cross(p_mean.transpose());
  const Positions residual = dc - motion.Velocity(p);
  motion.rms_residual = std::sqrt(residual.squaredNorm() / static_cast<double>(p.rows()));
  return motion;
}

Positions NonRigidFlow(const Positions& x, const Positions& flow, const RigidMotion& rigid) {
  if (x.rows() != flow.rows())
    ThrowError("non-rigid flow", "flow",
               std::to_string(flow.rows()) + " rows for " + std::to_string(x.rows()) + " points");
  return flow - rigid.Velocity(x);
}

Eigen::VectorXd FlowMagnitudes(const Positions& flow) { return flow.rowwise().norm(); }

FlowAnalysis AnalyzeFlow(const std::vector<Positions>& positions,
                         const std::vector<RigidMotion>& rigid) {
  const int frames = static_cast<int>(positions.size());
  if (frames < 1) ThrowError("flow analysis", "positions", "need at least one frame");
  if (static_cast<int>(rigid.size()) != frames - 1 && static_cast<int>(rigid.size()) != frames)
    ThrowError("flow analysis", "rigid motions",
               std::to_string(rigid.size()) + " given for " + std::to_string(frames) +
                   " frames, expected one per frame step");
  const Eigen::Index vertices = positions[0].rows();
  for (int f = 1; f < frames; ++f)
    if (positions[f].rows() != vertices)
      ThrowError("flow analysis", "frame " + std::to_string(f),
                 std::to_string(positions[f].rows()) + " vertices, frame 0 has " +
                     std::to_string(vertices));
  FlowAnalysis analysis;
  analysis.motion_energy = Eigen::VectorXd::Zero(vertices);
  analysis.non_rigid_energy = Eigen::VectorXd::Zero(vertices);
  for (int f = 0; f < frames; ++f) {
    if (f + 1 == frames) {
      analysis.flow.push_back(Positions::Zero(vertices, 3));
      analysis.rigid_flow.push_back(Positions::Zero(vertices, 3));
      analysis.non_rigid_flow.push_back(Positions::Zero(vertices, 3));
      break;
    }
    Positions flow = positions[f + 1] - positions[f];
    const Positions midpoints = 0.5 * (positions[f] + positions[f + 1]);
    Positions rigid_flow = rigid[f].Velocity(midpoints);
    Positions non_rigid = flow - rigid_flow;
    analysis.motion_energy += FlowMagnitudes(flow);
    analysis.non_rigid_energy += FlowMagnitudes(non_rigid);
    analysis.flow.push_back(std::move(flow));
    analysis.rigid_flow.push_back(std::move(rigid_flow));
    analysis.non_rigid_flow.push_back(std::move(non_rigid));
  }
  return analysis;
}

std::vector<RigidMotion> FitRigidMotions(const std::vector<Positions>& c0) {
  std::vector<RigidMotion> motions;
  for (std::size_t f = 0; f + 1 < c0.size(); ++f) {
    if (c0[f + 1].rows() != c0[f].rows())
      ThrowError("rigid motion fit", "frame " + std::to_string(f + 1),
                 "base control point count changes between frames");
    motions.push_back(FitRigidMotion(0.5 * (c0[f] + c0[f + 1]), c0[f + 1] - c0[f]));
  }
  return motions;
}

}  // namespace subflow::solver
