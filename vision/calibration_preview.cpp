#include "vision/calibration_preview.h"

#include <cmath>
#include <tuple>

#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace subflow::vision {
namespace {

// The 3D segment a–b sampled every few pixels' worth and drawn where it is in front.
void DrawSegment(const Camera& camera, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const cv::Scalar& colour,
                 int thickness, cv::Mat* image) {
  const int steps = 64;
  bool previous_valid = false;
  cv::Point2d previous;
  const double limit = 4.0 * std::max(camera.width(), camera.height());
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector3d X = a + (b - a) * (static_cast<double>(i) / steps);
    double depth = 0;
    const Eigen::Vector2d pinhole = camera.ProjectUndistorted(X, &depth);
    // Behind the camera, or so far out of the image that the distortion polynomial folds.
    const bool valid = depth > 1e-6 && camera.InImage(pinhole, -limit);
    const Eigen::Vector2d p = valid ? camera.Project(X) : Eigen::Vector2d::Zero();
    const cv::Point2d point(p.x(), p.y());
    if (valid && previous_valid) cv::line(*image, previous, point, colour, thickness, cv::LINE_AA);
    previous = point;
    previous_valid = valid;
  }
}

}  // namespace

cv::Mat DrawCalibrationPreview(const Camera& camera, const cv::Mat& frame, const Bounds& bounds,
                               const PreviewOptions& options) {
  if (frame.cols != camera.width() || frame.rows != camera.height())
    ThrowError("", "camera \"" + camera.name() + "\": preview", "expected a frame of the camera's size");
  cv::Mat image;
  cv::Mat eight = frame;
  if (frame.depth() == CV_16U) frame.convertTo(eight, CV_8U, 1.0 / 257);
  if (eight.channels() == 1) cv::cvtColor(eight, image, cv::COLOR_GRAY2BGR);
  else if (eight.channels() == 4) cv::cvtColor(eight, image, cv::COLOR_BGRA2BGR);
  else image = eight.clone();
  const int t = options.thickness;
  if (options.up) {
    int axis = 0;
    options.up->cwiseAbs().maxCoeff(&axis);
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const double s = options.grid_spacing;
    const double u0 = std::floor(bounds.min[u] / s) * s, u1 = std::ceil(bounds.max[u] / s) * s;
    const double v0 = std::floor(bounds.min[v] / s) * s, v1 = std::ceil(bounds.max[v] / s) * s;
    // Lines of constant u across [v0, v1], then of constant v across [u0, u1].
    for (const auto& [along, across, from, to, lo, hi] :
         {std::tuple{u, v, u0, u1, v0, v1}, std::tuple{v, u, v0, v1, u0, u1}})
      for (double a = from; a <= to + 1e-9; a += s) {
        Eigen::Vector3d p = Eigen::Vector3d::Zero(), q = Eigen::Vector3d::Zero();
        p[along] = q[along] = a;
        p[across] = lo;
        q[across] = hi;
        DrawSegment(camera, p, q, cv::Scalar(255, 255, 0), t, &image);
      }
  }
  for (int corner = 0; corner < 8; ++corner)
    for (int axis = 0; axis < 3; ++axis) {
      if (corner & (1 << axis)) continue;
      Eigen::Vector3d p, q;
      for (int k = 0; k < 3; ++k) p[k] = (corner & (1 << k)) ? bounds.max[k] : bounds.min[k];
      q = p;
      q[axis] = bounds.max[axis];
      DrawSegment(camera, p, q, cv::Scalar(0, 255, 255), t, &image);
    }
  const cv::Scalar axis_colours[3] = {cv::Scalar(0, 0, 255), cv::Scalar(0, 255, 0), cv::Scalar(255, 0, 0)};
  for (int axis = 0; axis < 3; ++axis)
    DrawSegment(camera, Eigen::Vector3d::Zero(), options.grid_spacing * Eigen::Vector3d::Unit(axis),
                axis_colours[axis], t + 2, &image);
  return image;
}

}  // namespace subflow::vision
