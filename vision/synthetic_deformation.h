// Smooth per-frame deformations of a synthetic subject's rest mesh: articulations with
// blended hinges, twist and bending, then a rigid motion of the whole — applied to the
// vertices, so the mesh keeps one connectivity and vertex i stays one material point.
//
// Time τ (scene time, τ = motion · frame). Every amplitude is modulated by a Wave:
//   sine     w(τ) = sin(2π τ / period + phase)            (oscillates in [−1, 1])
//   ramp     w(τ) = (1 − cos(2π τ / period + phase)) / 2   (starts at 0 for phase 0, in [0, 1])
// so that motions stay bounded for any number of frames.
//
// A BlendedRotation rotates a point x about the line (pivot, axis) by the angle
//   θ(x, τ) = amplitude_degrees · w(τ) · weight(x_rest)
// where the weight is evaluated at the REST position (material coordinate), so regions
// follow the material, not space:
//   region weight  Π_i S((n_i · x − d_i) / width_i) over soft half-spaces (S = smoothstep
//                  from 0 at −½ to 1 at +½: 1 well inside n · x > d, 0 well outside);
//                  a rigid part blended smoothly into the rest over `width`;
//   ramp weight    s = n · (x − pivot) / half_length: s for |s| ≤ ½, then a C¹ quadratic
//                  reaching ±1 at |s| = 1.5 and constant beyond; the rotation angle
//                  grows linearly along n — a TWIST when n ∥ axis, a BEND
//                  when n ⟂ axis.
// Rotations are applied in list order (parts first, then whole-body twists), each to the
// output of the previous one, about its pivot moved with the previous rotations (pivot
// carried as a material point), then the rigid motion:
//   x ← R(rotation_axis, rotation_degrees · w_r(τ)) (x − centre) + centre + translation · w_t(τ).
// Angles are blended, not displacements, so a blend zone bends instead of collapsing.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"

namespace subflow::vision {

struct Wave {
  enum class Kind { kSine, kRamp };
  Kind kind = Kind::kSine;
  double period = 120.0;  // τ units (frames at motion 1)
  double phase = 0.0;     // radians
  double operator()(double tau) const;
};

struct SoftHalfSpace {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit; weight → 1 on the side n · x > offset
  double offset = 0.0;                                // metres
  double width = 0.01;                                // metres over which the weight goes 0 → 1
};

struct BlendedRotation {
  std::string name;  // for messages and tests ("jaw", "tail", …)
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // rotation axis (normalized on use)
  double amplitude_degrees = 0.0;
  Wave wave;
  // Region weight (the default, `ramp_half_length` = 0): the product over `region`
  // (empty region = weight 1 everywhere). Ramp weight when ramp_half_length > 0.
  std::vector<SoftHalfSpace> region;
  Eigen::Vector3d ramp_direction = Eigen::Vector3d::UnitX();
  double ramp_half_length = 0.0;

  double Weight(const Eigen::Vector3d& rest) const;  // in [0, 1] (region) or [−1, 1] (ramp)
};

struct RigidPath {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotation_axis = Eigen::Vector3d::UnitZ();
  double rotation_degrees = 0.0;
  Wave rotation_wave;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // metres at w = 1
  Wave translation_wave;
};

struct Deformation {
  std::vector<BlendedRotation> rotations;
  RigidPath rigid;

  // Positions at time τ of the rest vertices (#V×3 → #V×3).
  geometry::Positions Apply(const geometry::Positions& rest, double tau) const;
  // One point (the same map).
  Eigen::Vector3d Apply(const Eigen::Vector3d& rest, double tau) const;

 private:
  // Where each rotation's pivot (a material point) is after the rotations before it.
  std::vector<Eigen::Vector3d> MovedPivots(double tau) const;
  Eigen::Vector3d ApplyRotations(const Eigen::Vector3d& rest, double tau,
                                 const std::vector<Eigen::Vector3d>& pivots, std::size_t count) const;
  Eigen::Vector3d ApplyRigid(const Eigen::Vector3d& x, double tau) const;
};

}  // namespace subflow::vision
