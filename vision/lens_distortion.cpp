#include "vision/lens_distortion.h"

#include <cmath>
#include <vector>

#include <Eigen/LU>
#include <opencv2/calib3d.hpp>

namespace subflow::vision {
namespace {

Eigen::Vector2d DistortOpenCv(const Eigen::Matrix<double, 8, 1>& d, const Eigen::Vector2d& xy,
                              Eigen::Matrix2d* jacobian) {
  const double k1 = d[0], k2 = d[1], p1 = d[2], p2 = d[3], k3 = d[4], k4 = d[5], k5 = d[6], k6 = d[7];
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double numerator = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double denominator = 1 + r2 * (k4 + r2 * (k5 + r2 * k6));
  const double radial = numerator / denominator;
  const Eigen::Vector2d out(x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
                            y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y);
  if (jacobian) {
    // d radial / d r² by the quotient rule.
    const double dnum = k1 + r2 * (2 * k2 + 3 * k3 * r2), dden = k4 + r2 * (2 * k5 + 3 * k6 * r2);
    const double dradial_dr2 = (dnum * denominator - numerator * dden) / (denominator * denominator);
    const double drad_dx = dradial_dr2 * 2 * x, drad_dy = dradial_dr2 * 2 * y;
    (*jacobian)(0, 0) = radial + x * drad_dx + 2 * p1 * y + 6 * p2 * x;
    (*jacobian)(0, 1) = x * drad_dy + 2 * p1 * x + 2 * p2 * y;
    (*jacobian)(1, 0) = y * drad_dx + 2 * p1 * x + 2 * p2 * y;
    (*jacobian)(1, 1) = radial + y * drad_dy + 6 * p1 * y + 2 * p2 * x;
  }
  return out;
}

Eigen::Vector2d DistortFisheye(const Eigen::Matrix<double, 8, 1>& d, const Eigen::Vector2d& xy,
                               Eigen::Matrix2d* jacobian) {
  const double r = xy.norm();
  if (r < 1e-12) {  // s(r) = θd / r → 1 and s'(r) → 0 at the axis
    if (jacobian) jacobian->setIdentity();
    return xy;
  }
  const double theta = std::atan(r), t2 = theta * theta;
  const double poly = 1 + t2 * (d[0] + t2 * (d[1] + t2 * (d[2] + t2 * d[3])));
  const double theta_d = theta * poly;
  const double s = theta_d / r;
  if (jacobian) {
    // ∂(s x)/∂x = s I + (s'(r) / r) x xᵀ with s' = (θd'(θ) θ'(r) r − θd) / r².
    const double dtheta_d = 1 + t2 * (3 * d[0] + t2 * (5 * d[1] + t2 * (7 * d[2] + t2 * 9 * d[3])));
    const double ds_dr = (dtheta_d / (1 + r * r) * r - theta_d) / (r * r);
    *jacobian = s * Eigen::Matrix2d::Identity() + (ds_dr / r) * xy * xy.transpose();
  }
  return s * xy;
}

}  // namespace

std::string DistortionModelName(DistortionModel model) {
  return model == DistortionModel::kFisheye ? "fisheye" : "opencv";
}

bool ParseDistortionModel(const std::string& text, DistortionModel* model) {
  if (text == "opencv") *model = DistortionModel::kOpenCV;
  else if (text == "fisheye") *model = DistortionModel::kFisheye;
  else return false;
  return true;
}

Eigen::VectorXd LensDistortion::OpenCvCoefficients() const {
  const int n = model == DistortionModel::kFisheye ? 4 : (IsRational() ? 8 : 5);
  return coefficients.head(n);
}

cv::Mat LensDistortion::OpenCvCoefficientsMat() const {
  const Eigen::VectorXd d = OpenCvCoefficients();
  cv::Mat out(1, static_cast<int>(d.size()), CV_64F);
  for (int i = 0; i < d.size(); ++i) out.at<double>(0, i) = d[i];
  return out;
}

Eigen::Vector2d LensDistortion::Distort(const Eigen::Vector2d& xy, Eigen::Matrix2d* jacobian) const {
  if (model == DistortionModel::kFisheye) return DistortFisheye(coefficients, xy, jacobian);
  return DistortOpenCv(coefficients, xy, jacobian);
}

Eigen::Vector2d LensDistortion::Undistort(const Eigen::Vector2d& distorted) const {
  if (IsIdentity()) return distorted;
  std::vector<cv::Point2d> source{{distorted.x(), distorted.y()}}, normalized;
  const cv::Mat identity = cv::Mat::eye(3, 3, CV_64F), d = OpenCvCoefficientsMat();
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-14);
  if (model == DistortionModel::kFisheye)
    cv::fisheye::undistortPoints(source, normalized, identity, d, cv::noArray(), cv::noArray(), criteria);
  else
    cv::undistortPoints(source, normalized, identity, d, cv::noArray(), cv::noArray(), criteria);
  Eigen::Vector2d xy(normalized[0].x, normalized[0].y);
  if (!xy.allFinite()) xy = distorted;
  for (int iteration = 0; iteration < 10; ++iteration) {
    Eigen::Matrix2d jacobian;
    const Eigen::Vector2d residual = Distort(xy, &jacobian) - distorted;
    if (residual.norm() < 1e-15) break;
    xy -= jacobian.partialPivLu().solve(residual);
  }
  return xy;
}

}  // namespace subflow::vision
