#include "vision/working_volume.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Dense>

#include "core/error.h"

namespace subflow::vision {
namespace {

std::string Format(double value) {
  std::ostringstream out;
  out.precision(4);
  out << value;
  return out.str();
}

// Counts, for every point of a res³ grid over [lo, hi], the cameras that see it, and
// returns the bounding box of the points seen by ≥ min_views cameras (invalid if none).
Bounds SeenBox(const std::vector<Camera>& cameras, const Eigen::Vector3d& lo,
               const Eigen::Vector3d& hi, int res, int min_views, double near_depth,
               Eigen::Vector3d* cell) {
  *cell = (hi - lo) / (res - 1);
  Bounds box;
  box.min.setConstant(std::numeric_limits<double>::infinity());
  box.max.setConstant(-std::numeric_limits<double>::infinity());
  for (int i = 0; i < res; ++i)
    for (int j = 0; j < res; ++j)
      for (int k = 0; k < res; ++k) {
        const Eigen::Vector3d X = lo + cell->cwiseProduct(Eigen::Vector3d(i, j, k));
        int views = 0;
        for (const Camera& camera : cameras) {
          double depth = 0;
          const Eigen::Vector2d pinhole = camera.ProjectUndistorted(X, &depth);
          if (depth <= near_depth) continue;
          // Far outside the pinhole image a distortion polynomial can fold back into the
          // image; those points are not seen.
          if (camera.HasDistortion() &&
              !camera.InImage(pinhole, -std::max(camera.width(), camera.height())))
            continue;
          if (camera.InImage(camera.Project(X))) ++views;
        }
        if (views >= min_views) {
          box.min = box.min.cwiseMin(X);
          box.max = box.max.cwiseMax(X);
        }
      }
  return box;
}

}  // namespace

void WorkingVolumeOptions::Check() const {
  if (!(min_camera_fraction > 0 && min_camera_fraction <= 1))
    ThrowError("WorkingVolumeOptions", "min_camera_fraction",
               "expected a value in (0, 1], got " + std::to_string(min_camera_fraction));
  if (grid_resolution < 4)
    ThrowError("WorkingVolumeOptions", "grid_resolution",
               "expected at least 4, got " + std::to_string(grid_resolution));
  if (!(near_fraction >= 0 && near_fraction < 1))
    ThrowError("WorkingVolumeOptions", "near_fraction",
               "expected a value in [0, 1), got " + std::to_string(near_fraction));
}

Bounds EstimateWorkingVolume(const std::vector<Camera>& cameras,
                             const WorkingVolumeOptions& options, const std::string& source) {
  options.Check();
  const int n = static_cast<int>(cameras.size());
  if (n < 2)
    ThrowError(source, "bounds",
               "absent, and it cannot be derived from " + std::to_string(n) +
                   " camera(s): at least 2 cameras must see the working volume; give "
                   "\"bounds\": {\"min\": [x, y, z], \"max\": [x, y, z]}");

  // 1. Look-at point: least-squares closest point to all optical axes.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero(), mean_center = Eigen::Vector3d::Zero(),
                  mean_direction = Eigen::Vector3d::Zero();
  for (const Camera& camera : cameras) {
    const Eigen::Vector3d a = camera.ViewDirection().normalized();
    const Eigen::Matrix3d orthogonal = Eigen::Matrix3d::Identity() - a * a.transpose();
    A += orthogonal;
    b += orthogonal * camera.Center();
    mean_center += camera.Center() / n;
    mean_direction += a / n;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(A);
  Eigen::Vector3d look_at;
  if (eigen.eigenvalues()(0) > 1e-3 * eigen.eigenvalues()(2)) {
    look_at = A.ldlt().solve(b);
  } else {
    // Nearly parallel axes (a forward-facing rig): look ahead by 5× the rig's spread.
    double spread = 0;
    for (const Camera& camera : cameras) spread = std::max(spread, (camera.Center() - mean_center).norm());
    if (spread == 0) spread = 1;
    // Opposed cameras on one axis cancel: then look along the first camera's axis.
    const Eigen::Vector3d ahead = mean_direction.norm() > 1e-6 ? mean_direction.normalized()
                                                              : cameras[0].ViewDirection().normalized();
    look_at = mean_center + 5 * spread * ahead;
  }

  // 2. Sampling cube around the look-at point.
  double half_size = 0;
  for (const Camera& camera : cameras) half_size = std::max(half_size, (camera.Center() - look_at).norm());
  const int min_views =
      std::max(2, static_cast<int>(std::ceil(options.min_camera_fraction * n - 1e-9)));
  const double near_depth = options.near_fraction * half_size;
  const int res = options.grid_resolution;

  // 3. Coarse pass, 4. refined pass over what it kept, 5. grow by one refined cell.
  Eigen::Vector3d cell;
  Bounds coarse = SeenBox(cameras, look_at.array() - half_size, look_at.array() + half_size, res,
                          min_views, near_depth, &cell);
  if (!(coarse.min.array() <= coarse.max.array()).all())
    ThrowError(source, "bounds",
               "absent, and no point of the " + Format(2 * half_size) +
                   "-wide cube around the cameras' look-at point is seen by " +
                   std::to_string(min_views) + " of the " + std::to_string(n) +
                   " cameras; give \"bounds\" explicitly");
  Bounds fine = SeenBox(cameras, coarse.min - cell, coarse.max + cell, res, min_views, near_depth, &cell);
  SUBFLOW_CHECK((fine.min.array() <= fine.max.array()).all(), "refined pass lost the coarse points");
  fine.min -= cell;
  fine.max += cell;
  return fine;
}

}  // namespace subflow::vision
