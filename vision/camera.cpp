#include "vision/camera.h"

#include <cmath>
#include <sstream>

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "vision/rotation.h"

namespace subflow::vision {

int ImageSideFromNumber(double value, const std::string& source, const std::string& field) {
  if (!(value >= 1 && value <= kMaxImageSide) || value != std::floor(value)) {
    std::ostringstream got;
    got << value;
    ThrowError(source, field,
               "expected a whole number of pixels in [1, " + std::to_string(kMaxImageSide) + "], got " + got.str());
  }
  return static_cast<int>(value);
}
namespace {

std::string Describe(const Eigen::MatrixXd& m) {
  std::ostringstream out;
  out.precision(17);
  out << "[";
  for (int r = 0; r < m.rows(); ++r) {
    out << (r ? ", [" : "[");
    for (int c = 0; c < m.cols(); ++c) out << (c ? ", " : "") << m(r, c);
    out << "]";
  }
  out << "]";
  return out.str();
}

cv::Mat ToCv(const Eigen::Matrix3d& m) {
  cv::Mat out(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.at<double>(r, c) = m(r, c);
  return out;
}

}  // namespace

Camera::Camera(std::string name, int width, int height, const Eigen::Matrix3d& K,
               const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
               const Eigen::VectorXd& distortion, const std::string& source,
               DistortionModel distortion_model)
    : name_(std::move(name)), width_(width), height_(height), K_(K), R_(R), t_(t) {
  const std::string where = "camera \"" + name_ + "\"";
  auto fail = [&](const std::string& field, const std::string& problem) {
    ThrowError(source, where + ": " + field, problem);
  };
  const std::string side_range = "[1, " + std::to_string(kMaxImageSide) + "]";
  if (width <= 0 || width > kMaxImageSide)
    fail("width", "expected an integer in " + side_range + ", got " + std::to_string(width));
  if (height <= 0 || height > kMaxImageSide)
    fail("height", "expected an integer in " + side_range + ", got " + std::to_string(height));
  if (static_cast<long long>(width) * height > kMaxImagePixels)
    fail("width × height", "expected at most " + std::to_string(kMaxImagePixels) + " pixels, got " +
                               std::to_string(width) + "×" + std::to_string(height));
  if (!K.allFinite()) fail("K", "expected finite values, got " + Describe(K));
  if (K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0 || K(2, 2) != 1)
    fail("K", "expected an upper-triangular intrinsic matrix with last row (0, 0, 1), got " +
                  Describe(K));
  if (!(K(0, 0) > 0) || !(K(1, 1) > 0))
    fail("K", "expected focal lengths fx = K[0][0] > 0 and fy = K[1][1] > 0, got " + Describe(K));
  const NearestRotationResult rotation = NearestRotation(R, source, where + ": R");
  R_ = rotation.rotation;
  rotation_correction_ = rotation.correction;
  if (rotation.correction > kRotationWarningTolerance)
    spdlog::warn("{}{}: R is {:.3g} from a rotation (max |R − R̂| over its entries, above {:.0e}); "
                 "using the nearest rotation R̂", source.empty() ? "" : source + ": ", where,
                 rotation.correction, kRotationWarningTolerance);
  if (!t.allFinite()) fail("t", "expected finite values, got " + Describe(t));

  const int n = static_cast<int>(distortion.size());
  distortion_.model = distortion_model;
  if (distortion_model == DistortionModel::kFisheye) {
    if (n != 0 && n != 4)
      fail("distortion", "expected 0 or 4 values (fisheye k1 k2 k3 k4), got " + std::to_string(n));
  } else if (n != 0 && n != 4 && n != 5 && n != 8) {
    fail("distortion", "expected 0, 4 (k1 k2 p1 p2), 5 (k1 k2 p1 p2 k3) or 8 (k1 k2 p1 p2 k3 k4 k5 k6) "
                       "values, got " + std::to_string(n));
  }
  if (!distortion.allFinite()) fail("distortion", "expected finite values, got " + Describe(distortion));
  for (int i = 0; i < n; ++i) distortion_.coefficients[i] = distortion[i];
  distortion_coefficients_ = distortion_.OpenCvCoefficients();
}

Eigen::Matrix<double, 3, 4> Camera::ProjectionMatrix() const {
  Eigen::Matrix<double, 3, 4> Rt;
  Rt << R_, t_;
  return K_ * Rt;
}

Eigen::Vector2d Camera::Project(const Eigen::Vector3d& X, double* depth) const {
  const Eigen::Vector3d Xc = ToCamera(X);
  if (depth) *depth = Xc.z();
  const Eigen::Vector2d normalized = Xc.head<2>() / Xc.z();
  const Eigen::Vector2d xy = HasDistortion() ? distortion_.Distort(normalized) : normalized;
  return (K_ * xy.homogeneous()).head<2>();
}

Eigen::Vector2d Camera::ProjectUndistorted(const Eigen::Vector3d& X, double* depth) const {
  const Eigen::Vector3d Xc = ToCamera(X);
  if (depth) *depth = Xc.z();
  return (K_ * (Xc / Xc.z())).head<2>();
}

Eigen::Matrix<double, 2, 3> Camera::ProjectionJacobian(const Eigen::Vector3d& X) const {
  // p = K (Xc / z) with Xc = R X + t:  ∂p/∂Xc = (1/z) [K₂ₓ₂ | −K₂ₓ₂ (x/z, y/z)ᵀ],  ∂Xc/∂X = R.
  const Eigen::Vector3d Xc = ToCamera(X);
  const double inv_z = 1.0 / Xc.z();
  const Eigen::Matrix2d K2 = K_.topLeftCorner<2, 2>();
  Eigen::Matrix<double, 2, 3> d_camera;
  d_camera.leftCols<2>() = K2 * inv_z;
  d_camera.col(2) = -K2 * Xc.head<2>() * (inv_z * inv_z);
  return d_camera * R_;
}

Eigen::Vector3d Camera::BackProjectUndistorted(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector3d direction_camera = K_.inverse() * pixel.homogeneous();
  return (R_.transpose() * direction_camera).normalized();
}

Eigen::Vector3d Camera::BackProject(const Eigen::Vector2d& pixel) const {
  if (!HasDistortion()) return BackProjectUndistorted(pixel);
  // The distorted normalized point, undistorted so that Project(BackProject(p)) = p to
  // ~1e-10 px even where OpenCV's iteration converges slowly (LensDistortion::Undistort).
  const Eigen::Vector2d target = (K_.inverse() * pixel.homogeneous()).head<2>();
  const Eigen::Vector2d xy = distortion_.Undistort(target);
  return (R_.transpose() * xy.homogeneous()).normalized();
}

bool Camera::InImage(const Eigen::Vector2d& pixel, double margin) const {
  // Pixel (0, 0) is the centre of the top-left pixel: the image covers [−½, w−½) × [−½, h−½).
  return pixel.x() >= -0.5 + margin && pixel.x() < width_ - 0.5 - margin &&
         pixel.y() >= -0.5 + margin && pixel.y() < height_ - 0.5 - margin;
}

cv::Mat Camera::UndistortImage(const cv::Mat& image, int interpolation) const {
  if (image.cols != width_ || image.rows != height_)
    ThrowError("", "camera \"" + name_ + "\": UndistortImage",
               "expected a " + std::to_string(width_) + "×" + std::to_string(height_) +
                   " image, got " + std::to_string(image.cols) + "×" + std::to_string(image.rows));
  if (!HasDistortion()) return image.clone();
  const cv::Mat d = distortion_.OpenCvCoefficientsMat();
  const cv::Mat K = ToCv(K_);
  cv::Mat map_x, map_y;
  if (distortion_.model == DistortionModel::kFisheye)
    cv::fisheye::initUndistortRectifyMap(K, d, cv::Mat::eye(3, 3, CV_64F), K, cv::Size(width_, height_),
                                         CV_32FC1, map_x, map_y);
  else
    cv::initUndistortRectifyMap(K, d, cv::noArray(), K, cv::Size(width_, height_), CV_32FC1, map_x, map_y);
  cv::Mat undistorted;
  cv::remap(image, undistorted, map_x, map_y, interpolation, cv::BORDER_CONSTANT, cv::Scalar());
  return undistorted;
}

}  // namespace subflow::vision
