// The synthetic rig of the voxel carving tests: six cameras around a sphere, its exact
// silhouettes (rays from OpenCV's undistortion, independent of Camera's), the working
// volume and trilinear occupancy of a carved grid.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "geometry/scalar_volume.h"
#include "vision/camera.h"
#include "vision/working_volume.h"

namespace subflow::vision::carving_rig {

using geometry::ScalarVolume;

// A camera at `centre` looking at `target`, world +z up (x = z × up, y = z × x).
inline Camera LookAt(const std::string& name, int width, int height, double focal,
              const Eigen::Vector3d& centre, const Eigen::Vector3d& target,
              const Eigen::VectorXd& distortion = Eigen::VectorXd()) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d up = std::abs(z.z()) > 0.99 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d x = z.cross(up).normalized();
  Eigen::Matrix3d R;
  R.row(0) = x;
  R.row(1) = z.cross(x);
  R.row(2) = z;
  Eigen::Matrix3d K;
  K << focal, 0, 0.5 * (width - 1), 0, focal, 0.5 * (height - 1), 0, 0, 1;
  return Camera(name, width, height, K, R, -R * centre, distortion);
}

inline Eigen::Vector3d Spherical(double distance, double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * M_PI / 180, e = elevation_deg * M_PI / 180;
  return distance * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
}

struct Sphere {
  Eigen::Vector3d centre{0.01, -0.015, 0.02};
  double radius = 0.08;
};

// Exact silhouette of the sphere in the RAW image: pixel centres whose ray meets the
// sphere. Rays of distorted pixels come from OpenCV's cv::undistortPoints (iterated to
// 1e-12), independently of Camera's own distortion code.
inline cv::Mat SphereMask(const Camera& camera, const Sphere& sphere) {
  std::vector<cv::Point2d> pixels, normalized;
  for (int y = 0; y < camera.height(); ++y)
    for (int x = 0; x < camera.width(); ++x) pixels.emplace_back(x, y);
  cv::Mat K(3, 3, CV_64F), d(1, 5, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) K.at<double>(r, c) = camera.K()(r, c);
  for (int i = 0; i < 5; ++i) d.at<double>(0, i) = camera.distortion()[i];
  cv::undistortPoints(pixels, normalized, K, d, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12));
  cv::Mat mask = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
  const Eigen::Vector3d to_centre = sphere.centre - camera.Center();
  for (size_t p = 0; p < pixels.size(); ++p) {
    const Eigen::Vector3d d_world =
        (camera.R().transpose() * Eigen::Vector3d(normalized[p].x, normalized[p].y, 1.0)).normalized();
    if (to_centre.dot(d_world) > 0 && (to_centre - to_centre.dot(d_world) * d_world).norm() <= sphere.radius)
      mask.at<uint8_t>(static_cast<int>(pixels[p].y), static_cast<int>(pixels[p].x)) = 255;
  }
  return mask;
}

// Six cameras at 0.6 m around the origin: a ring of four at 15° elevation, one from high
// above, one from below; 160 × 120 pixels, f = 200 px (≈ 333 px/m at the centre).
inline std::vector<Camera> SixCameras(const Eigen::VectorXd& distortion = Eigen::VectorXd()) {
  std::vector<Camera> cameras;
  const double directions[6][2] = {{20, 15}, {110, 15}, {200, 15}, {290, 15}, {60, 70}, {245, -50}};
  for (int c = 0; c < 6; ++c)
    cameras.push_back(LookAt("cam" + std::to_string(c), 160, 120, 200,
                             Spherical(0.6, directions[c][0], directions[c][1]),
                             Eigen::Vector3d::Zero(), distortion));
  return cameras;
}

inline const Bounds kBounds{Eigen::Vector3d::Constant(-0.15), Eigen::Vector3d::Constant(0.15)};

// Occupancy at X by trilinear interpolation of the voxel centres' values (0 outside the
// grid): ≥ 0.5 means X is inside the iso-surface at 0.5 that the mesher extracts.
inline double TrilinearOccupancy(const ScalarVolume& volume, const Eigen::Vector3d& X) {
  const Eigen::Vector3d g = (X - volume.origin) / volume.spacing;
  const Eigen::Vector3d f = g.array().floor();
  double value = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3i c = f.cast<int>() + Eigen::Vector3i(corner & 1, (corner >> 1) & 1, corner >> 2);
    if (!volume.InRange(c.x(), c.y(), c.z())) continue;
    const Eigen::Vector3d w = (Eigen::Vector3d::Ones() - (g - c.cast<double>()).cwiseAbs());
    value += w.prod() * volume.at(c.x(), c.y(), c.z());
  }
  return value;
}

}  // namespace subflow::vision::carving_rig
