// The subjects of vision/synthetic_subject.h and their meshing.
#include "vision/synthetic_subject.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/isosurface.h"

namespace subflow::vision {
namespace {

using Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;

Sdf HalfSpaceSdf(const Vector3d& normal, double offset) {  // inside where n · x > offset
  const Vector3d n = normal.normalized();
  return [=](const Vector3d& x) { return offset - n.dot(x); };
}

Wave Sine(double period, double phase = 0.0) { return {Wave::Kind::kSine, period, phase}; }
Wave Ramp(double period) { return {Wave::Kind::kRamp, period, 0.0}; }

BlendedRotation Hinge(std::string name, const Vector3d& pivot, const Vector3d& axis, double degrees,
                      Wave wave, std::vector<SoftHalfSpace> region) {
  BlendedRotation r;
  r.name = std::move(name);
  r.pivot = pivot;
  r.axis = axis;
  r.amplitude_degrees = degrees;
  r.wave = wave;
  r.region = std::move(region);
  return r;
}

BlendedRotation RampRotation(std::string name, const Vector3d& pivot, const Vector3d& axis, double degrees,
                             Wave wave, const Vector3d& direction, double half_length) {
  BlendedRotation r = Hinge(std::move(name), pivot, axis, degrees, wave, {});
  r.ramp_direction = direction;
  r.ramp_half_length = half_length;
  return r;
}

// A plate of half-thickness `half_thickness` along its local x (the first column of
// `rotation`), elliptic in its local (y, z) with semi-axes (ry, rz), edge rounded.
Sdf EarPlate(const Vector3d& centre, const Eigen::Matrix3d& rotation, double half_thickness, double ry,
             double rz) {
  const Eigen::Matrix3d to_local = rotation.transpose();
  return [=](const Vector3d& x) {
    const Vector3d q = to_local * (x - centre);
    const double ellipse = (std::hypot(q.y() / ry, q.z() / rz) - 1.0) * std::min(ry, rz);
    const Eigen::Vector2d d(std::abs(q.x()) - 0.2 * half_thickness, ellipse + 0.8 * half_thickness);
    return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0) - 0.8 * half_thickness;
  };
}

SdfSubject MakeBust() {
  SdfSubject s;
  s.name = "bust";
  Sdf head = SmoothUnionAll({EllipsoidSdf({0, 0.005, 0.025}, {0.07, 0.083, 0.092}),
                             EllipsoidSdf({0, -0.022, -0.04}, {0.052, 0.058, 0.045}),
                             CylinderSdf({0, 0.012, -0.13}, {0, 0.012, -0.03}, 0.042, 0.008)},
                            0.02);
  const Sdf brow = SmoothUnion(CapsuleSdf({-0.032, -0.066, 0.047}, {0, -0.074, 0.05}, 0.008),
                               CapsuleSdf({0, -0.074, 0.05}, {0.032, -0.066, 0.047}, 0.008), 0.004);
  head = SmoothUnion(head, brow, 0.01);
  const Sdf nose = SmoothUnion(CapsuleSdf({0, -0.083, 0.028}, {0, -0.101, -0.008}, 0.008),
                               SphereSdf({0, -0.099, -0.01}, 0.012), 0.006);
  head = SmoothUnion(head, nose, 0.008);
  for (double side : {-1.0, 1.0})  // eye sockets: ≈ 32 × 24 mm openings, 14 mm deep
    head = SmoothSubtract(head, EllipsoidSdf({side * 0.03, -0.07, 0.022}, {0.016, 0.014, 0.012}), 0.004);
  head = SmoothSubtract(head, EllipsoidSdf({0, -0.078, -0.03}, {0.024, 0.016, 0.005}), 0.003);  // mouth slit
  for (double side : {-1.0, 1.0}) {  // ear plates, 3 mm thick, rear edge standing ≈ 2 cm off the head
    const Sdf ear = EarPlate({side * 0.074, 0.018, 0.012}, AxisRotation(Vector3d::UnitZ(), -side * 25.0),
                             0.0015, 0.022, 0.03);
    head = SmoothUnion(head, ear, 0.003);
  }
  s.sdf = head;
  s.box_min = {-0.1, -0.125, -0.145};
  s.box_max = {0.1, 0.1, 0.125};
  // Jaw: in front (y < −0.03, blended over 2 cm), below the mouth line (z < −0.03, over
  // 1 cm), above the neck's base (z > −0.1); hinged below the ears.
  s.deformation.rotations.push_back(Hinge("jaw", {0, 0.0, -0.025}, Vector3d::UnitX(), 14.0, Ramp(96.0),
                                          {{{0, -1, 0}, 0.03, 0.02}, {{0, 0, -1}, 0.03, 0.01},
                                           {{0, 0, 1}, -0.1, 0.02}}));
  s.deformation.rigid.centre = {0, 0.012, 0};
  s.deformation.rigid.rotation_axis = Vector3d::UnitZ();
  s.deformation.rigid.rotation_degrees = 25.0;
  s.deformation.rigid.rotation_wave = Sine(120.0);
  return s;
}

SdfSubject MakeMug() {
  SdfSubject s;
  s.name = "mug";
  s.genus = 1;
  Sdf cup = SmoothSubtract(CylinderSdf({0, 0, -0.045}, {0, 0, 0.045}, 0.045, 0.004),
                           CylinderSdf({0, 0, -0.039}, {0, 0, 0.08}, 0.039, 0.004), 0.002);
  const Sdf handle = Intersect(TorusSdf({0.052, 0, 0}, Vector3d::UnitY(), 0.027, 0.007),
                               HalfSpaceSdf(Vector3d::UnitX(), 0.042));
  s.sdf = SmoothUnion(cup, handle, 0.005);
  s.box_min = {-0.05, -0.05, -0.05};
  s.box_max = {0.09, 0.05, 0.05};
  s.deformation.rotations.push_back(Hinge("handle", {0.045, 0, 0}, Vector3d::UnitY(), 10.0, Sine(70.0),
                                          {{{1, 0, 0}, 0.052, 0.012}}));
  s.deformation.rotations.push_back(RampRotation("bend", {0, 0, -0.045}, Vector3d::UnitY(), 8.0, Sine(90.0),
                                                 Vector3d::UnitZ(), 0.06));
  s.deformation.rigid.rotation_axis = Vector3d(0.3, 1.0, 0.2).normalized();
  s.deformation.rigid.rotation_degrees = 20.0;
  s.deformation.rigid.rotation_wave = Sine(110.0);
  s.deformation.rigid.translation = {0.015, 0.005, 0.008};
  s.deformation.rigid.translation_wave = Sine(80.0, 0.5);
  return s;
}

Sdf Figure(double cx) {
  std::vector<Sdf> parts = {EllipsoidSdf({cx, 0, 0}, {0.028, 0.02, 0.05}), SphereSdf({cx, 0, 0.078}, 0.021),
                            CapsuleSdf({cx, 0, 0.045}, {cx, 0, 0.06}, 0.01)};
  for (double side : {-1.0, 1.0}) {
    parts.push_back(CapsuleSdf({cx + side * 0.022, 0, 0.038}, {cx + side * 0.045, 0, -0.035}, 0.0065));
    parts.push_back(CapsuleSdf({cx + side * 0.012, 0, -0.035}, {cx + side * 0.014, 0, -0.11}, 0.009));
  }
  return SmoothUnionAll(parts, 0.008);
}

SdfSubject MakePair() {
  SdfSubject s;
  s.name = "pair";
  s.component_count = 2;
  const double a = -0.07, b = 0.07;
  const Sdf figure_a = Figure(a), figure_b = Figure(b);
  s.sdf = [figure_a, figure_b](const Vector3d& x) { return std::min(figure_a(x), figure_b(x)); };
  s.box_min = {-0.135, -0.05, -0.125};
  s.box_max = {0.135, 0.05, 0.105};
  const SoftHalfSpace left_figure{{-1, 0, 0}, 0.0, 0.01}, right_figure{{1, 0, 0}, 0.0, 0.01};
  auto& rotations = s.deformation.rotations;
  // Figure A: raises its outer (−x) arm sideways, and turns about its vertical axis.
  rotations.push_back(Hinge("arm", {a - 0.03, 0, 0.03}, Vector3d::UnitY(), 50.0, Ramp(100.0),
                            {{{-1, 0, 0}, -(a - 0.031), 0.004}, left_figure}));
  rotations.push_back(Hinge("turn", {a, 0, 0}, Vector3d::UnitZ(), 35.0, Sine(130.0), {left_figure}));
  // Figure B: swings its legs (opposite phases), bends forward at the waist, and sways
  // like a pendulum hung 1 m above it (±2 cm along y).
  for (double side : {-1.0, 1.0}) {
    rotations.push_back(Hinge("leg", {b + side * 0.012, 0, -0.035}, Vector3d::UnitX(), 15.0,
                              Sine(60.0, side > 0 ? kPi : 0.0),
                              {{{side, 0, 0}, side * b, 0.008}, {{0, 0, -1}, 0.03, 0.01}, right_figure}));
  }
  rotations.push_back(Hinge("waist", {b, 0, -0.02}, Vector3d::UnitX(), 15.0, Sine(90.0),
                            {{{0, 0, 1}, -0.02, 0.02}, right_figure}));
  rotations.push_back(Hinge("sway", {b, 0, 1.0}, Vector3d::UnitX(), 1.15, Sine(75.0, 1.0), {right_figure}));
  return s;
}

SdfSubject MakeCritter() {
  SdfSubject s;
  s.name = "critter";
  std::vector<Sdf> limbs = {EllipsoidSdf({0, 0, 0}, {0.068, 0.032, 0.032})};
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0})
      limbs.push_back(CapsuleSdf({sx * 0.042, sy * 0.02, -0.015}, {sx * 0.046, sy * 0.024, -0.085}, 0.006));
  limbs.push_back(CapsuleSdf({-0.062, 0, 0.008}, {-0.09, 0, 0.022}, 0.004));
  limbs.push_back(CapsuleSdf({-0.09, 0, 0.022}, {-0.11, 0, 0.05}, 0.004));
  limbs.push_back(CapsuleSdf({-0.11, 0, 0.05}, {-0.115, 0, 0.075}, 0.0035));
  Sdf body = SmoothUnionAll(limbs, 0.006);
  const Sdf head = SmoothUnionAll({CapsuleSdf({0.05, 0, 0.01}, {0.08, 0, 0.035}, 0.016),
                                   SphereSdf({0.088, 0, 0.04}, 0.024),
                                   EllipsoidSdf({0.112, 0, 0.032}, {0.018, 0.013, 0.011})},
                                  0.01);
  body = SmoothUnion(body, head, 0.01);
  for (double side : {-1.0, 1.0})  // ear plates 3 mm thick, tilted outwards
    body = SmoothUnion(body, EarPlate({0.082, side * 0.016, 0.068},
                                      AxisRotation(Vector3d::UnitX(), -side * 20.0) *
                                          AxisRotation(Vector3d::UnitZ(), 90.0),
                                      0.0015, 0.009, 0.015),
                       0.002);
  s.sdf = body;
  s.box_min = {-0.13, -0.05, -0.1};
  s.box_max = {0.14, 0.05, 0.095};
  auto& rotations = s.deformation.rotations;
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0})
      rotations.push_back(Hinge("leg", {sx * 0.042, sy * 0.02, -0.015}, Vector3d::UnitY(), 15.0,
                                Sine(50.0, sx * sy > 0 ? 0.0 : kPi),
                                {{{sx, 0, 0}, 0.02, 0.015}, {{0, sy, 0}, 0.0, 0.012}, {{0, 0, -1}, 0.012, 0.01}}));
  rotations.push_back(Hinge("tail", {-0.062, 0, 0.008}, Vector3d::UnitZ(), 30.0, Sine(40.0),
                            {{{-1, 0, 0}, 0.06, 0.01}}));
  rotations.push_back(Hinge("head", {0.055, 0, 0.012}, Vector3d::UnitZ(), 20.0, Sine(80.0, 0.7),
                            {{{1, 0, 0}, 0.055, 0.015}}));
  rotations.push_back(RampRotation("twist", {0, 0, 0}, Vector3d::UnitX(), 15.0, Sine(70.0), Vector3d::UnitX(), 0.06));
  s.deformation.rigid.rotation_axis = Vector3d::UnitZ();
  s.deformation.rigid.rotation_degrees = 20.0;
  s.deformation.rigid.rotation_wave = Sine(150.0);
  s.deformation.rigid.translation = {0.01, 0, 0};
  s.deformation.rigid.translation_wave = Sine(100.0);
  return s;
}

}  // namespace

std::vector<std::string> SdfSubjectNames() { return {"bust", "mug", "pair", "critter"}; }

bool IsSdfSubject(const std::string& name) {
  const auto names = SdfSubjectNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

SdfSubject MakeSdfSubject(const std::string& name) {
  if (name == "bust") return MakeBust();
  if (name == "mug") return MakeMug();
  if (name == "pair") return MakePair();
  if (name == "critter") return MakeCritter();
  ThrowError("synthetic subject", "scene", "expected bust, mug, pair or critter, got \"" + name + "\"");
}

void SdfMeshOptions::Check() const {
  if (!(voxel_size >= 2e-4 && voxel_size <= 0.02))
    ThrowError("synthetic subject", "voxel", "expected 0.0002..0.02 m, got " + std::to_string(voxel_size));
  if (!(facet_size_voxels >= 0.5 && facet_size_voxels <= 10.0))
    ThrowError("synthetic subject", "facet_size_voxels", "expected 0.5..10");
  if (newton_steps < 0 || newton_steps > 20) ThrowError("synthetic subject", "newton_steps", "expected 0..20");
}

geometry::TriangleMesh MeshSdfSubject(const SdfSubject& subject, const SdfMeshOptions& options,
                                      Progress* progress) {
  options.Check();
  const double h = options.voxel_size;
  const Vector3d origin = subject.box_min - Vector3d::Constant(3.0 * h);
  const Eigen::Vector3i n = ((subject.box_max - subject.box_min) / h).array().ceil().cast<int>() + 7;
  geometry::ScalarVolume volume(origin, h, n.x(), n.y(), n.z());
  ProgressBegin(progress, "synth: sampling the " + subject.name + " SDF", static_cast<std::size_t>(n.z()));
  tbb::parallel_for(0, n.z(), [&](int k) {
    for (int j = 0; j < n.y(); ++j)
      for (int i = 0; i < n.x(); ++i)
        volume.at(i, j, k) =
            static_cast<float>(std::clamp(0.5 - subject.sdf(volume.VoxelCenter(i, j, k)) / (4.0 * h), 0.0, 1.0));
  });
  ProgressEnd(progress);
  geometry::IsosurfaceOptions iso;
  iso.iso_value = 0.5;
  iso.smoothing_sigma_voxels = 0.0;
  iso.facet_size_voxels = options.facet_size_voxels;
  iso.facet_distance_voxels = 0.1;
  iso.facet_angle_degrees = 25.0;
  geometry::TriangleMesh mesh = geometry::ExtractIsosurface(volume, iso, nullptr, "synthetic " + subject.name);
  // Newton projection onto the SDF's zero set (the gradient step h/4 resolves 3 mm plates).
  tbb::parallel_for(Eigen::Index{0}, mesh.V.rows(), [&](Eigen::Index v) {
    Vector3d x = mesh.V.row(v).transpose();
    for (int step = 0; step < options.newton_steps; ++step) {
      const double value = subject.sdf(x);
      const Vector3d g = SdfGradient(subject.sdf, x, 0.25 * h);
      const double g2 = g.squaredNorm();
      if (!(g2 > 1e-12)) break;
      x -= value * g / g2;
    }
    mesh.V.row(v) = x.transpose();
  });
  return mesh;
}

}  // namespace subflow::vision
