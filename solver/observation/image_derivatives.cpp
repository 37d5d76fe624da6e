#include "solver/observation/image_derivatives.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace subflow::solver {
namespace {

cv::Mat Smooth(const cv::Mat& gray, double sigma) {
  if (sigma <= 0.0) return gray.clone();
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
  cv::Mat smoothed;
  cv::GaussianBlur(gray, smoothed, cv::Size(2 * radius + 1, 2 * radius + 1), sigma, sigma,
                   cv::BORDER_REPLICATE);
  return smoothed;
}

// Bilinear weights of the 2×2 neighbourhood of `pixel`; false when it leaves the image.
bool Footprint(int width, int height, const Eigen::Vector2d& pixel, int* x0, int* y0,
               double* fx, double* fy) {
  if (!std::isfinite(pixel.x()) || !std::isfinite(pixel.y())) return false;
  const double fx0 = std::floor(pixel.x()), fy0 = std::floor(pixel.y());
  if (fx0 < 0.0 || fy0 < 0.0 || fx0 + 1.0 > width - 1 || fy0 + 1.0 > height - 1) return false;
  *x0 = static_cast<int>(fx0);
  *y0 = static_cast<int>(fy0);
  *fx = pixel.x() - fx0;
  *fy = pixel.y() - fy0;
  return true;
}

double Bilinear(const cv::Mat& image, int x0, int y0, double fx, double fy) {
  const float* row0 = image.ptr<float>(y0);
  const float* row1 = image.ptr<float>(y0 + 1);
  return (1.0 - fy) * ((1.0 - fx) * row0[x0] + fx * row0[x0 + 1]) +
         fy * ((1.0 - fx) * row1[x0] + fx * row1[x0 + 1]);
}

}  // namespace

cv::Mat GrayFloat(const cv::Mat& image) {
  if (image.empty()) ThrowError("image derivatives", "image", "is empty");
  cv::Mat gray;
  switch (image.channels()) {
    case 1: gray = image; break;
    case 3: cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY); break;
    case 4: cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY); break;
    default:
      ThrowError("image derivatives", "image",
                 "expected 1, 3 or 4 channels, got " + std::to_string(image.channels()));
  }
  cv::Mat result;
  switch (gray.depth()) {
    case CV_8U: gray.convertTo(result, CV_32F, 1.0 / 255.0); break;
    case CV_16U: gray.convertTo(result, CV_32F, 1.0 / 65535.0); break;
    case CV_32F: result = gray.clone(); break;
    case CV_64F: gray.convertTo(result, CV_32F); break;
    default: ThrowError("image derivatives", "image", "expected 8-bit, 16-bit or float pixels");
  }
  return result;
}

cv::Mat LogHighPass(const cv::Mat& image, double sigma) {
  if (!std::isfinite(sigma) || sigma <= 0.0)
    ThrowError("image derivatives", "high-pass sigma", "expected a finite value > 0 (pixels)");
  cv::Mat log_intensity;
  cv::log(GrayFloat(image) + static_cast<float>(kLogEpsilon), log_intensity);
  return log_intensity - Smooth(log_intensity, sigma);
}

SmoothedImage SmoothImage(const cv::Mat& image, double sigma) {
  if (!std::isfinite(sigma) || sigma < 0.0)
    ThrowError("image derivatives", "sigma", "expected a finite value ≥ 0 (pixels)");
  SmoothedImage result;
  result.intensity = Smooth(GrayFloat(image), sigma);
  return result;
}

bool SampleImage(const SmoothedImage& image, const Eigen::Vector2d& pixel, double* intensity,
                 Eigen::Vector2d* gradient) {
  const int width = image.width(), height = image.height();
  int x0 = 0, y0 = 0;
  double fx = 0.0, fy = 0.0;
  if (!Footprint(width, height, pixel, &x0, &y0, &fx, &fy)) return false;
  const cv::Mat& I = image.intensity;
  *intensity = Bilinear(I, x0, y0, fx, fy);
  // Central differences at the 2×2 corners, the border replicated; ½(b − a) in float is
  // what filter2D's −½a + 0 + ½b rounds to (both products are exact).
  const auto difference = [](float a, float b) { return 0.5f * (b - a); };
  const int xm = std::max(x0 - 1, 0), xp = std::min(x0 + 2, width - 1);
  const int ym = std::max(y0 - 1, 0), yp = std::min(y0 + 2, height - 1);
  const float* r0 = I.ptr<float>(y0);
  const float* r1 = I.ptr<float>(y0 + 1);
  const float* rm = I.ptr<float>(ym);
  const float* rp = I.ptr<float>(yp);
  const double gx00 = difference(r0[xm], r0[x0 + 1]), gx10 = difference(r0[x0], r0[xp]);
  const double gx01 = difference(r1[xm], r1[x0 + 1]), gx11 = difference(r1[x0], r1[xp]);
  const double gy00 = difference(rm[x0], r1[x0]), gy10 = difference(rm[x0 + 1], r1[x0 + 1]);
  const double gy01 = difference(r0[x0], rp[x0]), gy11 = difference(r0[x0 + 1], rp[x0 + 1]);
  *gradient = Eigen::Vector2d((1.0 - fy) * ((1.0 - fx) * gx00 + fx * gx10) + fy * ((1.0 - fx) * gx01 + fx * gx11),
                              (1.0 - fy) * ((1.0 - fx) * gy00 + fx * gy10) + fy * ((1.0 - fx) * gy01 + fx * gy11));
  return true;
}

bool SampleScalar(const cv::Mat& image, const Eigen::Vector2d& pixel, double* value) {
  SUBFLOW_CHECK(image.type() == CV_32FC1, "SampleScalar expects a CV_32FC1 image");
  int x0 = 0, y0 = 0;
  double fx = 0.0, fy = 0.0;
  if (!Footprint(image.cols, image.rows, pixel, &x0, &y0, &fx, &fy)) return false;
  *value = Bilinear(image, x0, y0, fx, fy);
  return true;
}

SpatioTemporalDerivatives ComputeSpatioTemporalDerivatives(const cv::Mat& previous,
                                                           const cv::Mat& current,
                                                           const cv::Mat& next, double sigma) {
  if (previous.empty() && next.empty())
    ThrowError("image derivatives", "frames", "need the previous or the next frame for I_t");
  SpatioTemporalDerivatives result;
  result.spatial = SmoothImage(current, sigma);
  const cv::Size size = result.spatial.intensity.size();
  auto smoothed = [&](const cv::Mat& image, const char* which) {
    cv::Mat s = Smooth(GrayFloat(image), sigma);
    if (s.size() != size)
      ThrowError("image derivatives", which, "frame size differs from the current frame");
    return s;
  };
  if (!previous.empty() && !next.empty())
    result.temporal = 0.5 * (smoothed(next, "next") - smoothed(previous, "previous"));
  else if (!next.empty())
    result.temporal = smoothed(next, "next") - result.spatial.intensity;
  else
    result.temporal = result.spatial.intensity - smoothed(previous, "previous");
  return result;
}

}  // namespace subflow::solver
