// Lens distortion models of OpenCV, applied in normalized camera coordinates
// (x, y) = (Xc.x / Xc.z, Xc.y / Xc.z); the distorted pixel is K (x', y', 1)ᵀ.
//
//   kOpenCV — cv::projectPoints' model, coefficients k1 k2 p1 p2 k3 k4 k5 k6 (the
//     rational model; k4 = k5 = k6 = 0 is the common five-coefficient one):
//       r² = x² + y²,  radial = (1 + k1 r² + k2 r⁴ + k3 r⁶) / (1 + k4 r² + k5 r⁴ + k6 r⁶)
//       x' = x radial + 2 p1 x y + p2 (r² + 2 x²)
//       y' = y radial + p1 (r² + 2 y²) + 2 p2 x y
//   kFisheye — cv::fisheye's (Kannala–Brandt) model, coefficients k1 k2 k3 k4:
//       r = |(x, y)|,  θ = atan r,  θd = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸)
//       (x', y') = (θd / r) (x, y)          ((x', y') = (x, y) at r = 0)
//
// COLMAP's OPENCV / FULL_OPENCV / OPENCV_FISHEYE, Anipose's Camera and FisheyeCamera,
// EasyMocap and CMU Panoptic all use these formulas.
#pragma once

#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace subflow::vision {

enum class DistortionModel { kOpenCV, kFisheye };

// "opencv" / "fisheye" (as cameras.json writes it) and back; ParseDistortionModel returns
// false for any other text.
std::string DistortionModelName(DistortionModel model);
bool ParseDistortionModel(const std::string& text, DistortionModel* model);

struct LensDistortion {
  DistortionModel model = DistortionModel::kOpenCV;
  // kOpenCV: k1 k2 p1 p2 k3 k4 k5 k6; kFisheye: k1 k2 k3 k4 (the last four unused, zero).
  Eigen::Matrix<double, 8, 1> coefficients = Eigen::Matrix<double, 8, 1>::Zero();

  bool IsIdentity() const { return coefficients.cwiseAbs().maxCoeff() == 0; }
  bool IsRational() const {
    return model == DistortionModel::kOpenCV && coefficients.tail<3>().cwiseAbs().maxCoeff() > 0;
  }
  // The coefficients as OpenCV takes them: kOpenCV 5 values (8 when rational), kFisheye 4.
  Eigen::VectorXd OpenCvCoefficients() const;
  cv::Mat OpenCvCoefficientsMat() const;  // the same as a 1×n CV_64F row

  // (x', y') of the model at the normalized point xy, with ∂(x', y')/∂(x, y) if asked.
  Eigen::Vector2d Distort(const Eigen::Vector2d& xy, Eigen::Matrix2d* jacobian = nullptr) const;
  // The normalized point xy with Distort(xy) = distorted: OpenCV's iterative inversion
  // (cv::undistortPoints / cv::fisheye::undistortPoints) as the start, then Newton steps on
  // the exact model, so that |Distort(xy) − distorted| ≲ 1e-15 where the model is invertible.
  Eigen::Vector2d Undistort(const Eigen::Vector2d& distorted) const;
};

}  // namespace subflow::vision
