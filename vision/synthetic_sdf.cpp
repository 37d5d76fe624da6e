#include "vision/synthetic_sdf.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "core/error.h"

namespace subflow::vision {
namespace {

constexpr double kPi = 3.14159265358979323846;

double SmoothMin(double a, double b, double k) {
  if (k <= 0.0) return std::min(a, b);
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

}  // namespace

Sdf SphereSdf(const Eigen::Vector3d& centre, double radius) {
  SUBFLOW_CHECK(radius > 0.0, "sphere radius > 0");
  return [=](const Eigen::Vector3d& x) { return (x - centre).norm() - radius; };
}

Sdf EllipsoidSdf(const Eigen::Vector3d& centre, const Eigen::Vector3d& radii) {
  SUBFLOW_CHECK(radii.minCoeff() > 0.0, "ellipsoid radii > 0");
  // Quilez's bound: k0 (k0 − 1) / k1 with k0 = |p / r|, k1 = |p / r²|; exact on the surface
  // with the right gradient direction there.
  return [=](const Eigen::Vector3d& x) {
    const Eigen::Vector3d p = x - centre;
    const double k0 = p.cwiseQuotient(radii).norm();
    const double k1 = p.cwiseQuotient(radii.cwiseProduct(radii)).norm();
    if (k1 < 1e-12) return -radii.minCoeff();
    return k0 * (k0 - 1.0) / k1;
  };
}

Sdf CapsuleSdf(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) {
  SUBFLOW_CHECK(radius > 0.0, "capsule radius > 0");
  const Eigen::Vector3d ab = b - a;
  const double length2 = std::max(ab.squaredNorm(), 1e-24);
  return [=](const Eigen::Vector3d& x) {
    const double t = std::clamp((x - a).dot(ab) / length2, 0.0, 1.0);
    return (x - a - t * ab).norm() - radius;
  };
}

Sdf RoundBoxSdf(const Eigen::Vector3d& centre, const Eigen::Vector3d& half_extents,
                const Eigen::Matrix3d& rotation, double rounding) {
  SUBFLOW_CHECK(rounding >= 0.0 && rounding <= half_extents.minCoeff(), "box rounding in [0, min half extent]");
  const Eigen::Vector3d inner = half_extents - Eigen::Vector3d::Constant(rounding);
  const Eigen::Matrix3d to_local = rotation.transpose();
  return [=](const Eigen::Vector3d& x) {
    const Eigen::Vector3d q = (to_local * (x - centre)).cwiseAbs() - inner;
    const double outside = q.cwiseMax(0.0).norm();
    const double inside = std::min(q.maxCoeff(), 0.0);
    return outside + inside - rounding;
  };
}

Sdf TorusSdf(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis, double major_radius,
             double minor_radius) {
  SUBFLOW_CHECK(major_radius > minor_radius && minor_radius > 0.0, "torus radii R > r > 0");
  const Eigen::Vector3d n = axis.normalized();
  return [=](const Eigen::Vector3d& x) {
    const Eigen::Vector3d p = x - centre;
    const double height = p.dot(n);
    const double radial = (p - height * n).norm();
    return std::hypot(radial - major_radius, height) - minor_radius;
  };
}

Sdf CylinderSdf(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius, double rounding) {
  SUBFLOW_CHECK(radius > rounding && rounding >= 0.0, "cylinder radius > rounding ≥ 0");
  const Eigen::Vector3d centre = 0.5 * (a + b);
  const Eigen::Vector3d axis = (b - a).normalized();
  const double half_length = 0.5 * (b - a).norm();
  SUBFLOW_CHECK(half_length > rounding, "cylinder length > 2 rounding");
  return [=](const Eigen::Vector3d& x) {
    const Eigen::Vector3d p = x - centre;
    const double along = p.dot(axis);
    const Eigen::Vector2d q(std::abs((p - along * axis).norm()) - (radius - rounding),
                            std::abs(along) - (half_length - rounding));
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0) - rounding;
  };
}

Sdf SmoothUnion(Sdf a, Sdf b, double k) {
  return [a = std::move(a), b = std::move(b), k](const Eigen::Vector3d& x) { return SmoothMin(a(x), b(x), k); };
}

Sdf SmoothSubtract(Sdf a, Sdf b, double k) {
  return [a = std::move(a), b = std::move(b), k](const Eigen::Vector3d& x) { return -SmoothMin(-a(x), b(x), k); };
}

Sdf Intersect(Sdf a, Sdf b) {
  return [a = std::move(a), b = std::move(b)](const Eigen::Vector3d& x) { return std::max(a(x), b(x)); };
}

Sdf SmoothUnionAll(const std::vector<Sdf>& parts, double k) {
  SUBFLOW_CHECK(!parts.empty(), "a union of at least one part");
  return [parts, k](const Eigen::Vector3d& x) {
    double value = parts.front()(x);
    for (std::size_t i = 1; i < parts.size(); ++i) value = SmoothMin(value, parts[i](x), k);
    return value;
  };
}

Eigen::Vector3d SdfGradient(const Sdf& sdf, const Eigen::Vector3d& x, double h) {
  Eigen::Vector3d g;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    step[k] = h;
    g[k] = (sdf(x + step) - sdf(x - step)) / (2.0 * h);
  }
  return g;
}

Eigen::Matrix3d AxisRotation(const Eigen::Vector3d& axis, double degrees) {
  return Eigen::AngleAxisd(degrees * kPi / 180.0, axis.normalized()).toRotationMatrix();
}

}  // namespace subflow::vision
