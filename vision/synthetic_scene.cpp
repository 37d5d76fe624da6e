#include "vision/synthetic_scene.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "core/error.h"
#include "geometry/icosphere.h"
#include "vision/synthetic_subject.h"

namespace subflow::vision {
namespace {

using geometry::Positions;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;

double SmoothStep(double edge0, double edge1, double x) {
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// A Gaussian bump of the radius as a function of the angle to direction `axis`.
double Bump(const Eigen::Vector3d& unit, const Eigen::Vector3d& axis, double height, double sigma) {
  const double cos_angle = std::clamp(unit.dot(axis.normalized()), -1.0, 1.0);
  const double angle = std::acos(cos_angle);
  return height * std::exp(-0.5 * angle * angle / (sigma * sigma));
}

SyntheticScene MakeBlob(const geometry::TriangleMesh& sphere, const SyntheticSceneOptions& o) {
  SyntheticScene scene{"blob", sphere.F, sphere.V * 0.1, {}};
  struct Wave {
    Eigen::Vector3d k;
    double amplitude, omega, phase;
  };
  const Wave waves[3] = {{28.0 * Eigen::Vector3d(0.8, 0.3, 0.52).normalized(), 0.003, 0.3, 0.0},
                         {34.0 * Eigen::Vector3d(-0.4, 0.9, 0.2).normalized(), 0.003, 0.3, 1.3},
                         {40.0 * Eigen::Vector3d(0.1, -0.5, 0.86).normalized(), 0.003, 0.3, 2.6}};
  const Eigen::Vector3d velocity = 0.00127 * Eigen::Vector3d(1.0, -0.6, 0.5).normalized();
  for (int f = 0; f < o.frame_count; ++f) {
    const double tau = o.motion * (o.start_frame + f);
    Positions V(scene.rest.rows(), 3);
    for (Eigen::Index i = 0; i < V.rows(); ++i) {
      const Eigen::Vector3d x = scene.rest.row(i);
      const Eigen::Vector3d n = x.normalized();
      double displacement = 0.0;
      for (const Wave& w : waves) displacement += w.amplitude * std::sin(w.k.dot(x) - w.omega * tau + w.phase);
      V.row(i) = (x + displacement * n + tau * velocity).transpose();
    }
    scene.frames.push_back(std::move(V));
  }
  return scene;
}

SyntheticScene MakeRigid(const geometry::TriangleMesh& sphere, const SyntheticSceneOptions& o) {
  SyntheticScene scene{"rigid", sphere.F, Positions(sphere.V.rows(), 3), {}};
  const Eigen::Vector3d radii(0.10, 0.075, 0.06);
  for (Eigen::Index i = 0; i < sphere.V.rows(); ++i) {
    const Eigen::Vector3d u = sphere.V.row(i);
    const double scale = 1.0 + Bump(u, {0.6, 0.5, 0.6}, 0.25, 0.35) +
                         Bump(u, {-0.7, -0.2, 0.4}, 0.15, 0.25) - Bump(u, {0.1, -0.8, -0.3}, 0.12, 0.3);
    scene.rest.row(i) = (scale * radii.cwiseProduct(u)).transpose();
  }
  const Eigen::Vector3d centre = scene.rest.colwise().mean();
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, 0.2, 1.0).normalized();
  const Eigen::Vector3d velocity = 0.0015 * Eigen::Vector3d(-0.5, 1.0, 0.3).normalized();
  for (int f = 0; f < o.frame_count; ++f) {
    const double tau = o.motion * (o.start_frame + f);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(2.0 * kDegree * tau, axis).toRotationMatrix();
    Positions V(scene.rest.rows(), 3);
    for (Eigen::Index i = 0; i < V.rows(); ++i) {
      const Eigen::Vector3d x = scene.rest.row(i);
      V.row(i) = (R * (x - centre) + centre + tau * velocity).transpose();
    }
    scene.frames.push_back(std::move(V));
  }
  return scene;
}

SyntheticScene MakeHead(const geometry::TriangleMesh& sphere, const SyntheticSceneOptions& o) {
  SyntheticScene scene{"head", sphere.F, Positions(sphere.V.rows(), 3), {}};
  const Eigen::Vector3d radii(0.075, 0.09, 0.10);
  for (Eigen::Index i = 0; i < sphere.V.rows(); ++i) {
    const Eigen::Vector3d u = sphere.V.row(i);
    double scale = 1.0;
    scale += Bump(u, {0.0, -1.0, -0.05}, 0.22, 0.11);                               // nose
    scale += Bump(u, {0.35, -1.0, 0.38}, 0.06, 0.16) + Bump(u, {-0.35, -1.0, 0.38}, 0.06, 0.16);  // brows
    scale -= Bump(u, {0.33, -1.0, 0.2}, 0.05, 0.12) + Bump(u, {-0.33, -1.0, 0.2}, 0.05, 0.12);     // eyes
    scale += Bump(u, {0.6, -0.8, -0.2}, 0.05, 0.3) + Bump(u, {-0.6, -0.8, -0.2}, 0.05, 0.3);       // cheeks
    scale += Bump(u, {0.0, -0.75, -0.75}, 0.08, 0.25);                               // chin
    scene.rest.row(i) = (scale * radii.cwiseProduct(u)).transpose();
  }
  // Jaw: front (y < −0.02) and below the mouth line (z < −0.025), blended over 2 cm.
  const Eigen::Vector3d hinge(0.0, 0.01, -0.01);
  for (int f = 0; f < o.frame_count; ++f) {
    const double tau = o.motion * (o.start_frame + f);
    const Eigen::Matrix3d jaw = Eigen::AngleAxisd(0.8 * kDegree * tau, Eigen::Vector3d::UnitX()).toRotationMatrix();
    const Eigen::Matrix3d yaw = Eigen::AngleAxisd(1.2 * kDegree * tau, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Positions V(scene.rest.rows(), 3);
    for (Eigen::Index i = 0; i < V.rows(); ++i) {
      const Eigen::Vector3d x = scene.rest.row(i);
      const double weight = SmoothStep(-0.005, -0.025, x.z()) * SmoothStep(0.0, -0.04, x.y());
      const Eigen::Vector3d opened = x + weight * (jaw * (x - hinge) + hinge - x);
      V.row(i) = (yaw * opened).transpose();
    }
    scene.frames.push_back(std::move(V));
  }
  return scene;
}

SyntheticScene MakeSphere(const geometry::TriangleMesh& sphere, const SyntheticSceneOptions& o) {
  SyntheticScene scene{"sphere", sphere.F, sphere.V * 0.1, {}};
  const Eigen::Vector3d axis = Eigen::Vector3d(-0.2, 0.4, 1.0).normalized();
  const Eigen::Vector3d velocity = 0.0015 * Eigen::Vector3d(1.0, 0.5, -0.4).normalized();
  for (int f = 0; f < o.frame_count; ++f) {
    const double tau = o.motion * (o.start_frame + f);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(2.0 * kDegree * tau, axis).toRotationMatrix();
    Positions V = scene.rest * R.transpose();
    V.rowwise() += (tau * velocity).transpose();
    scene.frames.push_back(std::move(V));
  }
  return scene;
}

}  // namespace

void SyntheticSceneOptions::Check() const {
  const auto names = SyntheticSceneNames();
  if (std::find(names.begin(), names.end(), scene) == names.end())
    ThrowError("synthetic scene", "scene",
               "expected blob, rigid, head, sphere, bust, mug, pair or critter, got \"" + scene + "\"");
  if (start_frame < 0) ThrowError("synthetic scene", "start-frame", "expected ≥ 0");
  if (IsSdfSubject(scene)) {
    SdfMeshOptions mesh_options;
    mesh_options.voxel_size = voxel_size;
    mesh_options.Check();
  }
  if (frame_count < 1) ThrowError("synthetic scene", "frames", "expected at least 1 frame");
  if (!std::isfinite(motion) || motion < 0.0)
    ThrowError("synthetic scene", "motion", "expected a finite non-negative scale");
  if (subdivisions < 1 || subdivisions > 7)
    ThrowError("synthetic scene", "subdivisions", "expected 1..7, got " + std::to_string(subdivisions));
}

std::vector<std::string> SyntheticSceneNames() {
  std::vector<std::string> names = {"blob", "rigid", "head", "sphere"};
  for (const std::string& name : SdfSubjectNames()) names.push_back(name);
  return names;
}

SyntheticScene MakeSyntheticScene(const SyntheticSceneOptions& options, Progress* progress) {
  options.Check();
  if (IsSdfSubject(options.scene)) {
    const SdfSubject subject = MakeSdfSubject(options.scene);
    SdfMeshOptions mesh_options;
    mesh_options.voxel_size = options.voxel_size;
    const geometry::TriangleMesh rest = MeshSdfSubject(subject, mesh_options, progress);
    SyntheticScene scene{options.scene, rest.F, rest.V, {}};
    for (int f = 0; f < options.frame_count; ++f)
      scene.frames.push_back(subject.deformation.Apply(rest.V, options.motion * (options.start_frame + f)));
    return scene;
  }
  const geometry::TriangleMesh sphere = geometry::MakeIcosphere(options.subdivisions, 1.0);
  if (options.scene == "blob") return MakeBlob(sphere, options);
  if (options.scene == "rigid") return MakeRigid(sphere, options);
  if (options.scene == "sphere") return MakeSphere(sphere, options);
  return MakeHead(sphere, options);
}

}  // namespace subflow::vision
