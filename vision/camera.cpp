#include "vision/camera.h"

#include <cmath>
#include <sstream>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace subflow::vision {
namespace {

constexpr double kRotationTolerance = 1e-6;

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

// The OpenCV distortion model in normalized coordinates (x, y) = (Xc.x/Xc.z, Xc.y/Xc.z).
Eigen::Vector2d Distort(const Eigen::Matrix<double, 5, 1>& d, const Eigen::Vector2d& xy,
                        Eigen::Matrix2d* jacobian = nullptr) {
  const double k1 = d[0], k2 = d[1], p1 = d[2], p2 = d[3], k3 = d[4];
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  Eigen::Vector2d out(x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
                      y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y);
  if (jacobian) {
    const double dradial_dr2 = k1 + r2 * (2 * k2 + 3 * k3 * r2);
    const double drad_dx = dradial_dr2 * 2 * x, drad_dy = dradial_dr2 * 2 * y;
    (*jacobian)(0, 0) = radial + x * drad_dx + 2 * p1 * y + 6 * p2 * x;
    (*jacobian)(0, 1) = x * drad_dy + 2 * p1 * x + 2 * p2 * y;
    (*jacobian)(1, 0) = y * drad_dx + 2 * p1 * x + 2 * p2 * y;
    (*jacobian)(1, 1) = radial + y * drad_dy + 6 * p1 * y + 2 * p2 * x;
  }
  return out;
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
               const Eigen::VectorXd& distortion, const std::string& source)
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
  if (!R.allFinite()) fail("R", "expected finite values, got " + Describe(R));
  const double orthogonality = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthogonality > kRotationTolerance || std::abs(R.determinant() - 1) > kRotationTolerance) {
    std::ostringstream problem;
    problem << "expected a rotation (RᵀR = I and det R = +1 to " << kRotationTolerance
            << "), got max |RᵀR − I| = " << orthogonality << ", det R = " << R.determinant()
            << " for " << Describe(R);
    fail("R", problem.str());
  }
  if (!t.allFinite()) fail("t", "expected finite values, got " + Describe(t));
  const int n = static_cast<int>(distortion.size());
  if (n != 0 && n != 4 && n != 5 && n != 8)
    fail("distortion", "expected 0, 4 (k1 k2 p1 p2), 5 (k1 k2 p1 p2 k3) or 8 values, got " +
                           std::to_string(n));
  if (!distortion.allFinite()) fail("distortion", "expected finite values, got " + Describe(distortion));
  if (n == 8 && distortion.tail<3>().cwiseAbs().maxCoeff() != 0)
    fail("distortion", "the rational model's k4 k5 k6 must be 0 (subflow models k1 k2 p1 p2 k3 only), got " +
                           Describe(distortion.transpose()));
  for (int i = 0; i < std::min(n, 5); ++i) distortion_[i] = distortion[i];
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
  const Eigen::Vector2d xy = HasDistortion() ? Distort(distortion_, normalized) : normalized;
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
  // OpenCV's iterative inversion, then Newton steps on the exact model so that
  // Project(BackProject(p)) = p to ~1e-10 px even where the iteration converges slowly.
  std::vector<cv::Point2d> source{{pixel.x(), pixel.y()}}, normalized;
  cv::Mat d(1, 5, CV_64F);
  for (int i = 0; i < 5; ++i) d.at<double>(0, i) = distortion_[i];
  cv::Mat K = ToCv(K_);
  cv::undistortPoints(source, normalized, K, d, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-14));
  Eigen::Vector2d xy(normalized[0].x, normalized[0].y);
  const Eigen::Vector2d target = (K_.inverse() * pixel.homogeneous()).head<2>();  // distorted normalized
  for (int iteration = 0; iteration < 10; ++iteration) {
    Eigen::Matrix2d jacobian;
    const Eigen::Vector2d residual = Distort(distortion_, xy, &jacobian) - target;
    if (residual.norm() < 1e-15) break;
    xy -= jacobian.partialPivLu().solve(residual);
  }
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
  cv::Mat d(1, 5, CV_64F);
  for (int i = 0; i < 5; ++i) d.at<double>(0, i) = distortion_[i];
  const cv::Mat K = ToCv(K_);
  cv::Mat map_x, map_y;
  cv::initUndistortRectifyMap(K, d, cv::noArray(), K, cv::Size(width_, height_), CV_32FC1, map_x,
                              map_y);
  cv::Mat undistorted;
  cv::remap(image, undistorted, map_x, map_y, interpolation, cv::BORDER_CONSTANT, cv::Scalar());
  return undistorted;
}

}  // namespace subflow::vision
