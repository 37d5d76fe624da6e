#include "vision/synthetic_deformation.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <tbb/parallel_for.h>

namespace subflow::vision {
namespace {

constexpr double kPi = 3.14159265358979323846;

double SmoothStep01(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

Eigen::Matrix3d Rotation(const Eigen::Vector3d& axis, double degrees) {
  return Eigen::AngleAxisd(degrees * kPi / 180.0, axis.normalized()).toRotationMatrix();
}

}  // namespace

double Wave::operator()(double tau) const {
  const double angle = 2.0 * kPi * tau / period + phase;
  return kind == Kind::kSine ? std::sin(angle) : 0.5 * (1.0 - std::cos(angle));
}

double BlendedRotation::Weight(const Eigen::Vector3d& rest) const {
  if (ramp_half_length > 0.0) {
    const double s = std::clamp(ramp_direction.normalized().dot(rest - pivot) / ramp_half_length, -1.5, 1.5);
    // Linear in the middle, flattened smoothly to ±1 beyond |s| = 1 (C¹ at |s| = 0.5).
    const double a = std::abs(s);
    const double u = std::min(a - 0.5, 1.0);
    return std::copysign(a <= 0.5 ? a : 0.5 + u - 0.5 * u * u, s);
  }
  double weight = 1.0;
  for (const SoftHalfSpace& h : region) weight *= SmoothStep01((h.normal.dot(rest) - h.offset) / h.width + 0.5);
  return weight;
}

std::vector<Eigen::Vector3d> Deformation::MovedPivots(double tau) const {
  std::vector<Eigen::Vector3d> pivots;
  for (std::size_t k = 0; k < rotations.size(); ++k)
    pivots.push_back(ApplyRotations(rotations[k].pivot, tau, pivots, k));
  return pivots;
}

Eigen::Vector3d Deformation::ApplyRotations(const Eigen::Vector3d& rest, double tau,
                                            const std::vector<Eigen::Vector3d>& pivots,
                                            std::size_t count) const {
  Eigen::Vector3d x = rest;
  for (std::size_t k = 0; k < count; ++k) {
    const BlendedRotation& r = rotations[k];
    const double angle = r.amplitude_degrees * r.wave(tau) * r.Weight(rest);
    if (angle != 0.0) x = Rotation(r.axis, angle) * (x - pivots[k]) + pivots[k];
  }
  return x;
}

Eigen::Vector3d Deformation::ApplyRigid(const Eigen::Vector3d& x, double tau) const {
  const RigidPath& g = rigid;
  const Eigen::Matrix3d R = Rotation(g.rotation_axis, g.rotation_degrees * g.rotation_wave(tau));
  return R * (x - g.centre) + g.centre + g.translation * g.translation_wave(tau);
}

Eigen::Vector3d Deformation::Apply(const Eigen::Vector3d& rest, double tau) const {
  return ApplyRigid(ApplyRotations(rest, tau, MovedPivots(tau), rotations.size()), tau);
}

geometry::Positions Deformation::Apply(const geometry::Positions& rest, double tau) const {
  const std::vector<Eigen::Vector3d> pivots = MovedPivots(tau);
  geometry::Positions V(rest.rows(), 3);
  tbb::parallel_for(Eigen::Index{0}, rest.rows(), [&](Eigen::Index i) {
    const Eigen::Vector3d x = rest.row(i).transpose();
    V.row(i) = ApplyRigid(ApplyRotations(x, tau, pivots, rotations.size()), tau).transpose();
  });
  return V;
}

}  // namespace subflow::vision
