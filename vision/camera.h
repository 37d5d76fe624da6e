// A calibrated pinhole camera with optional OpenCV lens distortion, in the convention of
// ../shared/DATASET.md (OpenCV / COLMAP):
//   camera coordinates  Xc = R X + t   (+z forward, +x right, +y down)
//   pixel               p = (fx Xc.x / Xc.z + cx, fy Xc.y / Xc.z + cy) (+ skew K(0,1))
//   pixel (0, 0) is the CENTRE of the top-left pixel; P = K [R | t] (method eq. 4).
// Distortion (vision/lens_distortion.h: OpenCV's k1 k2 p1 p2 k3 [k4 k5 k6] or its fisheye
// k1..k4) is applied by Project in normalized coordinates, as cv::projectPoints does. The
// reconstruction works on undistorted images (see UndistortImage), so its hot paths use
// ProjectUndistorted and its Jacobian.
//
// Calibrations as they are: R may be a near-rotation as files print it (6–8 digits); it
// is replaced by the nearest rotation (vision/rotation.h), with a warning (spdlog) when
// the correction exceeds kRotationWarningTolerance. Only a clear non-rotation (mirrored,
// scaled) is an error.
#pragma once

#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "vision/lens_distortion.h"

namespace subflow::vision {

// The largest image side a camera may have (px): beyond any sensor, and small enough that
// the per-pixel buffers of a camera (images, z-buffers, silhouettes) can be allocated.
// Readers refuse larger sizes before allocating anything for them.
inline constexpr int kMaxImageSide = 1 << 15;
// The most pixels an image may have (16384², ~268 Mpx: beyond 8K video by 8×).
inline constexpr long long kMaxImagePixels = 1LL << 28;

// An image side that a calibration file gives as a number (XML, TOML, YAML, JSON): a whole
// number of pixels in [1, kMaxImageSide], else a subflow::Error "<source>: <field>: expected
// …, got <value>" (also for NaN and values beyond int, which are never converted).
int ImageSideFromNumber(double value, const std::string& source, const std::string& field);

class Camera {
 public:
  Camera() = default;
  // `distortion`: kOpenCV 0, 4 (k1 k2 p1 p2), 5 (+ k3) or 8 (+ k4 k5 k6) values;
  // kFisheye 0 or 4 (k1 k2 k3 k4). Throws subflow::Error naming `source` when K is not a
  // valid intrinsic matrix (fx, fy > 0, last row (0, 0, 1)), R is not a near-rotation
  // (NearestRotation), sizes are not positive, the distortion has another length, or any
  // value is not finite.
  Camera(std::string name, int width, int height, const Eigen::Matrix3d& K,
         const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
         const Eigen::VectorXd& distortion = Eigen::VectorXd(), const std::string& source = "",
         DistortionModel distortion_model = DistortionModel::kOpenCV);

  const std::string& name() const { return name_; }
  int width() const { return width_; }
  int height() const { return height_; }
  const Eigen::Matrix3d& K() const { return K_; }
  const Eigen::Matrix3d& R() const { return R_; }
  const Eigen::Vector3d& t() const { return t_; }
  // The coefficients in OpenCV's order: kOpenCV k1 k2 p1 p2 k3 (5 values, zeros when the
  // camera has none; 8 with k4 k5 k6 when they are not all zero), kFisheye k1 k2 k3 k4.
  const Eigen::VectorXd& distortion() const { return distortion_coefficients_; }
  DistortionModel distortion_model() const { return distortion_.model; }
  const LensDistortion& lens_distortion() const { return distortion_; }
  bool HasDistortion() const { return !distortion_.IsIdentity(); }
  // max |R_given − R| of the re-orthonormalization (0 when R was given exactly).
  double rotation_correction() const { return rotation_correction_; }

  Eigen::Vector3d Center() const { return -R_.transpose() * t_; }  // in world coordinates
  Eigen::Vector3d ViewDirection() const { return R_.row(2).transpose(); }  // optical axis
  Eigen::Matrix<double, 3, 4> ProjectionMatrix() const;                  // K [R | t]

  Eigen::Vector3d ToCamera(const Eigen::Vector3d& X) const { return R_ * X + t_; }
  // Pixel of a world point including distortion; depth (Xc.z) returned if asked.
  Eigen::Vector2d Project(const Eigen::Vector3d& X, double* depth = nullptr) const;
  // Pixel of a world point in the undistorted image (pure pinhole K [R | t]).
  Eigen::Vector2d ProjectUndistorted(const Eigen::Vector3d& X, double* depth = nullptr) const;
  // ∂p/∂X, the 2×3 Jacobian of ProjectUndistorted at X (method eq. 24's ∂p_k/∂P).
  Eigen::Matrix<double, 2, 3> ProjectionJacobian(const Eigen::Vector3d& X) const;
  // Unit direction (world) of the ray through an undistorted pixel; the ray starts at Center().
  Eigen::Vector3d BackProjectUndistorted(const Eigen::Vector2d& pixel) const;
  // Ray through a pixel of the distorted (raw) image.
  Eigen::Vector3d BackProject(const Eigen::Vector2d& pixel) const;
  // True when pixel ∈ [−½ + margin, w − ½ − margin) × [−½ + margin, h − ½ − margin): the
  // image area in the pixel-centre convention, shrunk by `margin` pixels (negative grows it).
  bool InImage(const Eigen::Vector2d& pixel, double margin = 0.0) const;

  // Resamples a raw image to the undistorted pinhole camera with the same K.
  cv::Mat UndistortImage(const cv::Mat& image, int interpolation = 1 /* cv::INTER_LINEAR */) const;

 private:
  std::string name_;
  int width_ = 0, height_ = 0;
  Eigen::Matrix3d K_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_ = Eigen::Vector3d::Zero();
  LensDistortion distortion_;
  Eigen::VectorXd distortion_coefficients_ = Eigen::VectorXd::Zero(5);
  double rotation_correction_ = 0;
};

}  // namespace subflow::vision
