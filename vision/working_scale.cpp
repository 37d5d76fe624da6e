#include "vision/working_scale.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace subflow::vision {

Camera ScaledCamera(const Camera& camera, double scale) {
  SUBFLOW_CHECK(scale > 0 && scale <= 1, "working scale must be in (0, 1]");
  if (scale == 1) return camera;
  const int width = std::max(1, static_cast<int>(std::lround(camera.width() * scale)));
  const int height = std::max(1, static_cast<int>(std::lround(camera.height() * scale)));
  const double a = static_cast<double>(width) / camera.width(), b = static_cast<double>(height) / camera.height();
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(0, 0) = a;
  S(1, 1) = b;
  S(0, 2) = 0.5 * a - 0.5;  // pixel centres: a (c + ½) − ½
  S(1, 2) = 0.5 * b - 0.5;
  return Camera(camera.name(), width, height, S * camera.K(), camera.R(), camera.t(), camera.distortion(), "",
                camera.distortion_model());
}

cv::Mat ResizeToCamera(const cv::Mat& image, const Camera& working, bool mask) {
  const cv::Size size(working.width(), working.height());
  if (image.size() == size) return image;
  cv::Mat resized;
  cv::resize(image, resized, size, 0, 0, cv::INTER_AREA);
  if (mask) cv::threshold(resized, resized, 127, 255, cv::THRESH_BINARY);
  return resized;
}

double EvidenceScale(const Camera& camera, const Bounds& bounds, double voxel_size, double voxel_pixels) {
  if (!(voxel_pixels > 0) || !(voxel_size > 0)) return 1;
  const double depth = camera.ToCamera(bounds.Center()).z();
  if (!(depth > 0)) return 1;
  const double focal = 0.5 * (camera.K()(0, 0) + camera.K()(1, 1));
  const double pixels = focal * voxel_size / depth;
  return std::min(1.0, voxel_pixels / pixels);
}

double SurfaceScale(const Camera& camera, const geometry::Positions& V, const geometry::Faces& F,
                    double edge_pixels, double* median_pixels) {
  if (median_pixels) *median_pixels = 0;
  if (F.rows() == 0) return 1;
  std::vector<Eigen::Vector2d> pixels(V.rows());
  std::vector<char> seen(V.rows(), 0);
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    double depth = 0;
    pixels[v] = camera.ProjectUndistorted(V.row(v).transpose(), &depth);
    seen[v] = depth > 0 && camera.InImage(pixels[v]);
  }
  std::vector<double> lengths;
  lengths.reserve(F.rows() * 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int e = 0; e < 3; ++e) {
      const int i = F(f, e), j = F(f, (e + 1) % 3);
      if (i < j && seen[i] && seen[j]) lengths.push_back((pixels[i] - pixels[j]).norm());
    }
  if (lengths.empty()) return 1;
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  const double median = lengths[lengths.size() / 2];
  if (median_pixels) *median_pixels = median;
  return edge_pixels > 0 && median > 0 ? std::min(1.0, edge_pixels / median) : 1.0;
}

std::vector<Camera> ScaledCameras(const std::vector<Camera>& cameras, const std::vector<double>& scales) {
  SUBFLOW_CHECK(cameras.size() == scales.size(), "one working scale per camera");
  std::vector<Camera> scaled;
  scaled.reserve(cameras.size());
  for (std::size_t k = 0; k < cameras.size(); ++k) scaled.push_back(ScaledCamera(cameras[k], scales[k]));
  return scaled;
}

}  // namespace subflow::vision
