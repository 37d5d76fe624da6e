#include "output/view_cameras.h"

#include <cmath>

#include <Eigen/Geometry>

#include "core/error.h"

namespace subflow::output {

vision::Camera LookAtCamera(const std::string& name, int width, int height, double focal,
                            const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  const Eigen::Vector3d forward = (target - eye).normalized();
  Eigen::Vector3d right = forward.cross(up);
  if (right.norm() < 1e-9) right = forward.unitOrthogonal();  // looking along `up`
  right.normalize();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d R;
  R.row(0) = right.transpose();
  R.row(1) = down.transpose();
  R.row(2) = forward.transpose();
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(0, 0) = K(1, 1) = focal;
  K(0, 2) = (width - 1) / 2.0;
  K(1, 2) = (height - 1) / 2.0;
  return vision::Camera(name, width, height, K, R, -R * eye, Eigen::VectorXd(), name);
}

std::vector<vision::Camera> TurntableCameras(const geometry::Positions& V, const Eigen::Vector3d& up_direction,
                                             const TurntableOptions& options) {
  if (options.count < 1 || options.width < 8 || options.height < 8 || !(options.fill > 0 && options.fill <= 1) ||
      !(options.focal > 0))
    ThrowError("turntable options", "", "expected count ≥ 1, sizes ≥ 8 px, fill in (0, 1], focal > 0");
  const Eigen::Vector3d up = up_direction.normalized();
  const Eigen::Vector3d centre = (V.colwise().minCoeff() + V.colwise().maxCoeff()).transpose() / 2.0;
  const double radius = std::max(1e-9, (V.rowwise() - centre.transpose()).rowwise().norm().maxCoeff());
  // The sphere's angular radius asin(r / d) spans fill · side / 2 pixels: d = r / sin(atan(..)).
  const double half_angle = std::atan(options.fill * std::min(options.width, options.height) / 2.0 / options.focal);
  const double distance = radius / std::sin(half_angle);
  const Eigen::Vector3d first = up.unitOrthogonal();
  const double elevation = options.elevation_degrees * M_PI / 180.0;
  std::vector<vision::Camera> cameras;
  for (int k = 0; k < options.count; ++k) {
    const double azimuth = 2.0 * M_PI * k / options.count;
    const Eigen::Vector3d around = Eigen::AngleAxisd(azimuth, up) * first;
    const Eigen::Vector3d eye = centre + distance * (std::cos(elevation) * around + std::sin(elevation) * up);
    cameras.push_back(LookAtCamera("view" + std::to_string(k), options.width, options.height, options.focal, eye,
                                   centre, up));
  }
  return cameras;
}

Eigen::Vector3d CamerasUp(const std::vector<vision::Camera>& cameras) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const vision::Camera& camera : cameras) sum -= camera.R().row(1).transpose();
  return sum.norm() > 1e-6 * std::max<std::size_t>(1, cameras.size()) ? Eigen::Vector3d(sum.normalized())
                                                                       : Eigen::Vector3d::UnitZ();
}

}  // namespace subflow::output
