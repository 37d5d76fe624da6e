#include "vision/camera_rig.h"

#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>

#include "core/error.h"

namespace subflow::vision {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string CameraName(int k) {
  char name[16];
  std::snprintf(name, sizeof(name), "cam%02d", k);
  return name;
}

Eigen::Vector3d OnSphere(double distance, double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * kPi / 180.0, e = elevation_deg * kPi / 180.0;
  return distance * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
}

}  // namespace

void CameraRigOptions::Check() const {
  if (rig != "ring" && rig != "dome" && rig != "partial-dome" && rig != "front")
    ThrowError("camera rig", "rig", "expected ring, dome, partial-dome or front, got \"" + rig + "\"");
  if (camera_count < 2 || camera_count > 100)
    ThrowError("camera rig", "cameras", "expected 2..100, got " + std::to_string(camera_count));
  if (width < 8 || height < 8 || width > 8192 || height > 8192)
    ThrowError("camera rig", "width/height", "expected 8..8192 pixels");
  if (!std::isfinite(focal) || focal < 0.0) ThrowError("camera rig", "focal", "expected ≥ 0 (0 = default)");
  if (!(distance > 0.0) || !std::isfinite(distance)) ThrowError("camera rig", "distance", "expected > 0");
  if (!(elevation_deg > -89.0 && elevation_deg < 89.0))
    ThrowError("camera rig", "elevation", "expected −89..89 degrees");
  if (!(narrow_focal_factor >= 1.0) || !std::isfinite(narrow_focal_factor))
    ThrowError("camera rig", "narrow_focal_factor", "expected ≥ 1");
}

Camera LookAtCamera(const std::string& name, int width, int height, double focal,
                    const Eigen::Vector3d& centre, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - centre).normalized();
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  if (z.cross(up).norm() < 1e-6) up = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x = z.cross(up).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  Eigen::Matrix3d K;
  K << focal, 0.0, (width - 1) / 2.0, 0.0, focal, (height - 1) / 2.0, 0.0, 0.0, 1.0;
  return Camera(name, width, height, K, R, -R * centre);
}

std::vector<Camera> MakeCameraRig(const CameraRigOptions& options, const Eigen::Vector3d& target) {
  options.Check();
  const double focal = options.focal > 0.0 ? options.focal : 420.0 * options.width / 320.0;
  const int n = options.camera_count;
  std::vector<Camera> cameras;
  auto add = [&](double azimuth, double elevation, double f) {
    cameras.push_back(LookAtCamera(CameraName(static_cast<int>(cameras.size())), options.width,
                                   options.height, f, target + OnSphere(options.distance, azimuth, elevation),
                                   target));
  };
  if (options.rig == "ring") {
    for (int k = 0; k < n; ++k) add(-90.0 + 360.0 * k / n, options.elevation_deg, focal);
  } else if (options.rig == "dome") {
    const int ring_count = n - 1;
    const int low = std::max(1, static_cast<int>(std::lround(0.6 * ring_count)));
    const int high = ring_count - low;
    for (int k = 0; k < low; ++k) add(-90.0 + 360.0 * k / low, options.elevation_deg, focal);
    for (int k = 0; k < high; ++k) add(-90.0 + 360.0 * (k + 0.5) / high, 50.0, focal);
    add(0.0, 90.0, focal);
  } else if (options.rig == "front") {
    for (int k = 0; k < n; ++k)
      add(-165.0 + 150.0 * k / (n - 1), options.elevation_deg + (k % 2 == 0 ? 0.0 : 25.0), focal);
  } else {  // partial-dome: the front half of the azimuths, two elevations
    const int low = (n + 1) / 2, high = n - low;
    for (int k = 0; k < low; ++k) {
      const double azimuth = -180.0 + 180.0 * (low > 1 ? static_cast<double>(k) / (low - 1) : 0.5);
      add(azimuth, options.elevation_deg, cameras.size() % 3 == 2 ? focal * options.narrow_focal_factor : focal);
    }
    for (int k = 0; k < high; ++k) {
      const double azimuth = -180.0 + 180.0 * (k + 0.5) / high;
      add(azimuth, 45.0, cameras.size() % 3 == 2 ? focal * options.narrow_focal_factor : focal);
    }
  }
  return cameras;
}

Camera SupersampledCamera(const Camera& camera, int factor) {
  SUBFLOW_CHECK(factor >= 1, "supersampling factor ≥ 1");
  // x_fine = factor (x + 0.5) − 0.5 maps the coarse image point x to fine pixel units.
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(0, 0) = S(1, 1) = factor;
  S(0, 2) = S(1, 2) = 0.5 * (factor - 1);
  return Camera(camera.name(), camera.width() * factor, camera.height() * factor, S * camera.K(),
                camera.R(), camera.t());
}

}  // namespace subflow::vision
