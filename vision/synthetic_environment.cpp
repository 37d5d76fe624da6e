#include "vision/synthetic_environment.h"

#include <cmath>

#include <Eigen/Geometry>

#include "core/error.h"
#include "geometry/icosphere.h"
#include "vision/camera_rig.h"

namespace subflow::vision {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kWallHeight = 1.5;
constexpr int kQuadCells = 6;

// A grid of kQuadCells² quads over the parallelogram corner + [0,1]·u + [0,1]·v, facing u × v.
TexturedMesh Quad(const Eigen::Vector3d& corner, const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  const int n = kQuadCells;
  TexturedMesh quad;
  quad.V.resize((n + 1) * (n + 1), 3);
  quad.F.resize(2 * n * n, 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      quad.V.row(j * (n + 1) + i) = (corner + u * (static_cast<double>(i) / n) + v * (static_cast<double>(j) / n)).transpose();
  int face = 0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      quad.F.row(face++) << a, b, c;
      quad.F.row(face++) << a, c, d;
    }
  }
  quad.rest = quad.V;
  return quad;
}

TexturedMesh Ellipsoid(const Eigen::Vector3d& radii, const Eigen::Vector3d& texture_offset) {
  const geometry::TriangleMesh sphere = geometry::MakeIcosphere(3, 1.0);
  TexturedMesh mesh;
  mesh.V = sphere.V * radii.asDiagonal();
  mesh.F = sphere.F;
  mesh.rest = mesh.V.rowwise() + texture_offset.transpose();
  return mesh;
}

TexturedMesh Moved(const TexturedMesh& mesh, const Eigen::Vector3d& offset) {
  TexturedMesh moved = mesh;
  moved.V.rowwise() += offset.transpose();
  return moved;
}

}  // namespace

void EnvironmentOptions::Check() const {
  if (kind != "none" && kind != "floor" && kind != "room")
    ThrowError("synth", "environment", "expected none, floor or room, got \"" + kind + "\"");
  if (distractors != "none" && distractors != "walker" && distractors != "crosser" && distractors != "both")
    ThrowError("synth", "distractors", "expected none, walker, crosser or both, got \"" + distractors + "\"");
  if (shadow_samples < 1 || shadow_samples > 64) ThrowError("synth", "shadow_samples", "expected 1..64");
  if (!(shadow_cone_degrees >= 0.0 && shadow_cone_degrees <= 20.0))
    ThrowError("synth", "shadow_cone_degrees", "expected 0..20");
  if (!(shadow_bias > 0.0 && shadow_bias < 0.1)) ThrowError("synth", "shadow_bias", "expected (0, 0.1) m");
}

void AppendMesh(TexturedMesh* mesh, const TexturedMesh& part) {
  const Eigen::Index v0 = mesh->V.rows(), f0 = mesh->F.rows();
  mesh->V.conservativeResize(v0 + part.V.rows(), 3);
  mesh->rest.conservativeResize(v0 + part.V.rows(), 3);
  mesh->F.conservativeResize(f0 + part.F.rows(), 3);
  mesh->V.bottomRows(part.V.rows()) = part.V;
  mesh->rest.bottomRows(part.V.rows()) = part.rest;
  mesh->F.bottomRows(part.F.rows()) = part.F.array() + static_cast<int>(v0);
}

SyntheticEnvironment::SyntheticEnvironment(const EnvironmentOptions& options, const Eigen::Vector3d& subject_low,
                                           const Eigen::Vector3d& subject_high, const std::vector<Camera>& cameras,
                                           double camera_distance)
    : options_(options) {
  options_.Check();
  centre_ = 0.5 * (subject_low + subject_high);
  floor_z_ = subject_low.z() - 0.002;
  const double R = camera_distance + 0.3, H = kWallHeight;
  const double cx = centre_.x(), cy = centre_.y(), fz = floor_z_;
  if (options_.kind != "none") AppendMesh(&static_, Quad({cx - R, cy - R, fz}, {2 * R, 0, 0}, {0, 2 * R, 0}));
  if (options_.kind == "room") {
    AppendMesh(&static_, Quad({cx - R, cy + R, fz}, {2 * R, 0, 0}, {0, 0, H}));
    AppendMesh(&static_, Quad({cx + R, cy - R, fz}, {-2 * R, 0, 0}, {0, 0, H}));
    AppendMesh(&static_, Quad({cx + R, cy + R, fz}, {0, -2 * R, 0}, {0, 0, H}));
    AppendMesh(&static_, Quad({cx - R, cy - R, fz}, {0, 2 * R, 0}, {0, 0, H}));
  }
  walker_ = Ellipsoid({0.05, 0.05, 0.225}, {3.0, 0.0, 0.0});
  crosser_ = Ellipsoid({0.04, 0.04, 0.04}, {-3.0, 0.0, 0.0});
  SUBFLOW_CHECK(!cameras.empty(), "an environment needs the rig");
  const Camera& first = cameras.front();
  crosser_base_ = first.Center() + 0.2 * first.ViewDirection();
  crosser_direction_ = first.R().row(0).transpose();
}

TexturedMesh SyntheticEnvironment::AtFrame(int frame) const {
  TexturedMesh mesh = static_;
  const std::string& d = options_.distractors;
  if (d == "walker" || d == "both") {
    const Eigen::Vector3d at(centre_.x() + 0.45 * std::sin(2.0 * kPi * frame / 150.0), centre_.y() + 0.42,
                             floor_z_ + 0.225);
    AppendMesh(&mesh, Moved(walker_, at));
  }
  if (d == "crosser" || d == "both")
    AppendMesh(&mesh, Moved(crosser_, crosser_base_ + 0.25 * std::sin(2.0 * kPi * frame / 60.0 + 1.0) * crosser_direction_));
  return mesh;
}

SoftShadows::SoftShadows(const EnvironmentOptions& options, const Eigen::Vector3d& light_direction,
                         const geometry::Positions& subject_V, const geometry::Faces& subject_F)
    : bias_(options.shadow_bias) {
  if (!options.shadows) return;
  const Eigen::Vector3d low = subject_V.colwise().minCoeff(), high = subject_V.colwise().maxCoeff();
  const Eigen::Vector3d centre = 0.5 * (low + high);
  const double radius = 0.5 * (high - low).norm();
  const Eigen::Vector3d L = light_direction.normalized();
  const Eigen::Vector3d e1 = L.unitOrthogonal(), e2 = L.cross(e1);
  const int n = options.shadow_samples, size = 1024;
  const double cone = options.shadow_cone_degrees * kPi / 180.0, distance = 20.0;
  for (int i = 0; i < n; ++i) {
    const double r = cone * std::sqrt((i + 0.5) / n), phi = 2.399963229728653 * i;
    const Eigen::Vector3d direction = (L + std::tan(r) * (std::cos(phi) * e1 + std::sin(phi) * e2)).normalized();
    const double focal = 0.5 * size * distance / (1.15 * radius);
    const Camera light = LookAtCamera("light", size, size, focal, centre + distance * direction, centre);
    maps_.emplace_back(light, subject_V, subject_F);
  }
}

double SoftShadows::LightFraction(const Eigen::Vector3d& X) const {
  if (maps_.empty()) return 1.0;
  int lit = 0;
  for (const ZBuffer& map : maps_) {
    const Eigen::Vector2d p = map.camera().ProjectUndistorted(X);
    if (!map.camera().InImage(p) || map.IsVisible(X, bias_)) ++lit;
  }
  return static_cast<double>(lit) / static_cast<double>(maps_.size());
}

}  // namespace subflow::vision
