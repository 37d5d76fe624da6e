// Signed-distance functions (SDFs) for building synthetic subjects out of primitives.
//
// An Sdf maps a world point x (metres) to a signed value s(x): s < 0 inside, s > 0
// outside, s = 0 on the surface; |∇s| ≈ 1 near the surface (exact for spheres, capsules,
// boxes and tori; the ellipsoid and the smooth combinations are first-order bounds, which
// is all the iso-surface extraction and the Newton projection of synthetic_subject.h
// need: they only use the zero set and the gradient direction).
//
// Combinations (k = blend radius, metres; k = 0 is the sharp version):
//   SmoothUnion(a, b, k)     = min(a, b) − h²k/4,  h = max(k − |a − b|, 0)/k  (polynomial
//                              smooth minimum: a fillet of radius ≈ k where a and b meet)
//   SmoothSubtract(a, b, k)  = −SmoothUnion(−a, b, k) … i.e. a with b carved out
//   Intersect(a, b)          = max(a, b)
// Primitives (all positions in world metres):
//   Sphere(c, r), Ellipsoid(c, radii), Capsule(a, b, r) (segment ab swept by a ball of
//   radius r), RoundBox(c, half_extents, rotation, rounding) (a box whose local axes are
//   the columns of `rotation`, edges rounded by `rounding` ≤ min half extent), Torus(c,
//   axis, R, r) (tube radius r around a circle of radius R in the plane ⟂ axis through c),
//   Cylinder(a, b, r, rounding) (capped cylinder between the centres of its end discs).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace subflow::vision {

using Sdf = std::function<double(const Eigen::Vector3d&)>;

Sdf SphereSdf(const Eigen::Vector3d& centre, double radius);
Sdf EllipsoidSdf(const Eigen::Vector3d& centre, const Eigen::Vector3d& radii);
Sdf CapsuleSdf(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius);
Sdf RoundBoxSdf(const Eigen::Vector3d& centre, const Eigen::Vector3d& half_extents,
                const Eigen::Matrix3d& rotation, double rounding);
Sdf TorusSdf(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis, double major_radius,
             double minor_radius);
Sdf CylinderSdf(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius, double rounding);

Sdf SmoothUnion(Sdf a, Sdf b, double k);
Sdf SmoothSubtract(Sdf a, Sdf b, double k);  // a minus b
Sdf Intersect(Sdf a, Sdf b);
// Smooth union of a list, folded left with one blend radius.
Sdf SmoothUnionAll(const std::vector<Sdf>& parts, double k);

// Central-difference gradient of `sdf` at x with step h (metres).
Eigen::Vector3d SdfGradient(const Sdf& sdf, const Eigen::Vector3d& x, double h);

// Rotation by `degrees` about the unit `axis` (a convenience for placing primitives).
Eigen::Matrix3d AxisRotation(const Eigen::Vector3d& axis, double degrees);

}  // namespace subflow::vision
