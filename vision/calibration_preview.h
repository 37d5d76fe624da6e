// A picture to check a calibration by eye: a camera's frame with the working volume's
// box, the floor grid (when the world has an up axis) and the world axes at the origin
// drawn through the camera's own projection (distortion included, so straight 3D lines
// may curve). `subflow import --preview` writes one per camera.
#pragma once

#include <optional>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "vision/camera.h"
#include "vision/working_volume.h"

namespace subflow::vision {

struct PreviewOptions {
  std::optional<Eigen::Vector3d> up;  // unit axis (±x, ±y, ±z): floor grid in the plane through 0 normal to it
  double grid_spacing = 0.5;          // world units between floor grid lines
  int thickness = 2;                  // pixels
};

// `frame` (8-bit, 1 or 3 channels, the camera's size) as BGR with the drawing on it:
// the box in yellow, the floor grid in cyan, axes x red, y green, z blue (1 grid step long).
cv::Mat DrawCalibrationPreview(const Camera& camera, const cv::Mat& frame, const Bounds& bounds,
                               const PreviewOptions& options = {});

}  // namespace subflow::vision
