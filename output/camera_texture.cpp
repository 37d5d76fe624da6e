#include "output/camera_texture.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace subflow::output {

cv::Mat ToBgr8(const cv::Mat& image) {
  cv::Mat eight;
  if (image.depth() == CV_16U) image.convertTo(eight, CV_8U, 1.0 / 257.0);
  else if (image.depth() == CV_8U) eight = image;
  else image.convertTo(eight, CV_8U, 255.0);
  cv::Mat bgr;
  if (eight.channels() == 1) cv::cvtColor(eight, bgr, cv::COLOR_GRAY2BGR);
  else if (eight.channels() == 4) cv::cvtColor(eight, bgr, cv::COLOR_BGRA2BGR);
  else bgr = eight.clone();
  return bgr;
}

CameraTexture::CameraTexture(const vision::Dataset& dataset, int frame, const geometry::Positions& V,
                             const geometry::Faces& F, const CameraTextureOptions& options)
    : dataset_(dataset), options_(options) {
  if (options_.depth_tolerance <= 0) {
    double length = 0;
    for (Eigen::Index f = 0; f < F.rows(); ++f) length += (V.row(F(f, 1)) - V.row(F(f, 0))).norm();
    options_.depth_tolerance = 0.5 * length / std::max<Eigen::Index>(1, F.rows());
  }
  zbuffers_ = vision::RenderZBuffers(dataset.cameras(), V, F);
  for (int c = 0; c < dataset.camera_count(); ++c) {
    cv::Mat rgb;
    cv::cvtColor(ToBgr8(dataset.Image(c, frame)), rgb, cv::COLOR_BGR2RGB);
    rgb.convertTo(rgb, CV_32FC3, 1.0 / 255.0);
    images_.push_back(rgb);
  }
}

bool CameraTexture::Colour(const Eigen::Vector3d& X, const Eigen::Vector3d& n, Eigen::Vector3f* rgb) const {
  std::vector<std::pair<double, int>> seen;  // (weight, camera)
  for (int c = 0; c < static_cast<int>(zbuffers_.size()); ++c) {
    const vision::Camera& camera = dataset_.camera(c);
    const double w = n.dot((camera.Center() - X).normalized());
    if (w > options_.min_cosine && zbuffers_[static_cast<std::size_t>(c)].IsVisible(X, options_.depth_tolerance))
      seen.emplace_back(w * w, c);
  }
  if (seen.empty()) return false;
  std::sort(seen.rbegin(), seen.rend());
  seen.resize(std::min<std::size_t>(seen.size(), static_cast<std::size_t>(std::max(1, options_.blend))));
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  float weights = 0;
  for (const auto& [weight, c] : seen) {
    const Eigen::Vector2d p = dataset_.camera(c).Project(X);
    cv::Mat sample;
    cv::getRectSubPix(images_[static_cast<std::size_t>(c)], cv::Size(1, 1), cv::Point2f(p.x(), p.y()), sample);
    const cv::Vec3f value = sample.at<cv::Vec3f>(0, 0);
    sum += static_cast<float>(weight) * Eigen::Vector3f(value[0], value[1], value[2]);
    weights += static_cast<float>(weight);
  }
  *rgb = sum / weights;
  return true;
}

}  // namespace subflow::output
