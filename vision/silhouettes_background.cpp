#include "vision/silhouettes_background.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "vision/camera.h"
#include "vision/working_volume.h"

namespace subflow::vision {
namespace {

// sRGB: V = 12.92 L (L ≤ 0.0031308), else 1.055 L^(1/2.4) − 0.055.
float SrgbDecode(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}
// dV/dL at the decoded value L.
float SrgbSlope(float linear) {
  return linear <= 0.0031308f ? 12.92f : (1.055f / 2.4f) * std::pow(linear, 1.0f / 2.4f - 1.0f);
}

// Per pixel and channel a = s·L^I and b = s·L^B (file comment of the header), CV_32FC(C).
void SlopeWeighted(const cv::Mat& image, const cv::Mat& background, cv::Mat* a, cv::Mat* b) {
  const cv::Mat image_linear = DecodeSrgb(image), background_linear = DecodeSrgb(background);
  *a = cv::Mat(image.size(), image_linear.type());
  *b = cv::Mat(image.size(), image_linear.type());
  const int values_per_row = image.cols * image_linear.channels();
  for (int y = 0; y < image.rows; ++y) {
    const float* li = image_linear.ptr<float>(y);
    const float* lb = background_linear.ptr<float>(y);
    float* ar = a->ptr<float>(y);
    float* br = b->ptr<float>(y);
    for (int i = 0; i < values_per_row; ++i) {
      const float slope = SrgbSlope(li[i]);
      ar[i] = slope * li[i];
      br[i] = slope * lb[i];
    }
  }
}

// Sum over channels of a CV_32FC(C) image, CV_32FC1.
cv::Mat SumChannels(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat sum;
  cv::transform(image, sum, cv::Mat::ones(1, image.channels(), CV_32F));
  return sum;
}

}  // namespace

cv::Mat DecodeSrgb(const cv::Mat& encoded) {
  SUBFLOW_CHECK(encoded.depth() == CV_32F, "DecodeSrgb expects CV_32F values in [0, 1]");
  cv::Mat linear(encoded.size(), encoded.type());
  const int values_per_row = encoded.cols * encoded.channels();
  for (int y = 0; y < encoded.rows; ++y) {
    const float* in = encoded.ptr<float>(y);
    float* out = linear.ptr<float>(y);
    for (int i = 0; i < values_per_row; ++i) out[i] = SrgbDecode(in[i]);
  }
  return linear;
}

namespace {

// Σ over the window W(q) of image(p)·k(p − q), for every q: a correlation with kernel k.
cv::Mat WindowSum(const cv::Mat& image, const cv::Mat& kernel) {
  cv::Mat sum;
  cv::filter2D(image, sum, CV_32F, kernel, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
  return sum;
}

// A window shape: the pixels of W(q) relative to q (a square or a line), whether the gain
// may vary across it (a plane) or not, and the windows a pixel takes gains from.
struct WindowShape {
  int radius = 1;
  cv::Mat kernel;                      // CV_32F (2r + 1)², 1 on the window's pixels
  bool ramp = false;                   // gain α + β·u + γ·v, (u, v) = (p − q) / r
  std::vector<cv::Point> neighbours;   // offsets q − p of the windows that lend p their gain
};

// A pixel p takes gains from the windows that contain it: those centred at p − o for the
// window's own offsets o (the windows are symmetric about their centre).
WindowShape Square(int radius) {
  WindowShape shape{radius, cv::Mat::ones(2 * radius + 1, 2 * radius + 1, CV_32F), true, {}};
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx) shape.neighbours.emplace_back(dx, dy);
  return shape;
}

WindowShape Line(int radius, cv::Point direction) {
  WindowShape shape{radius, cv::Mat::zeros(2 * radius + 1, 2 * radius + 1, CV_32F), false, {}};
  for (int k = -radius; k <= radius; ++k) {
    shape.kernel.at<float>(radius + k * direction.y, radius + k * direction.x) = 1.0f;
    shape.neighbours.emplace_back(k * direction.x, k * direction.y);
  }
  return shape;
}

// The gain field of every window of one shape, fitted to "a ≈ g·b" by least squares; NaN
// α where the window is no shadow window (misfit above the tolerance, or the gain at q
// outside its range).
struct WindowGains {
  WindowShape shape;
  cv::Mat alpha, beta, gamma;  // CV_32FC1 each
};

WindowGains FitWindowGains(const cv::Mat& bb, const cv::Mat& ab, const cv::Mat& aa, int channels,
                           double tolerance, const WindowShape& shape, const SilhouetteOptions& options) {
  const int w = shape.radius, side = 2 * w + 1;
  cv::Mat u(side, side, CV_32F), v(side, side, CV_32F);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) u.at<float>(y, x) = (x - w) / float(w), v.at<float>(y, x) = (y - w) / float(w);
  u = u.mul(shape.kernel), v = v.mul(shape.kernel);
  // Normal equations M θ = h, θ = (α, β, γ), from window sums with the kernels 1, u, v, u², uv, v².
  const cv::Mat m00 = WindowSum(bb, shape.kernel), h0 = WindowSum(ab, shape.kernel), s = WindowSum(aa, shape.kernel);
  cv::Mat m01, m02, m11, m12, m22, h1, h2;
  if (shape.ramp) {
    m01 = WindowSum(bb, u), m02 = WindowSum(bb, v), m11 = WindowSum(bb, u.mul(u)), m12 = WindowSum(bb, u.mul(v));
    m22 = WindowSum(bb, v.mul(v)), h1 = WindowSum(ab, u), h2 = WindowSum(ab, v);
  }
  const double samples = channels * cv::sum(shape.kernel)[0];
  const double tolerance_squared = tolerance * tolerance;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  WindowGains gains{shape, cv::Mat(bb.size(), CV_32FC1, cv::Scalar(nan)), cv::Mat::zeros(bb.size(), CV_32FC1),
                    cv::Mat::zeros(bb.size(), CV_32FC1)};
  for (int y = 0; y < bb.rows; ++y)
    for (int x = 0; x < bb.cols; ++x) {
      const double n = m00.at<float>(y, x);
      if (!(n > 1e-8 * samples)) {  // no light on the background: no gain to fit, plain difference
        gains.alpha.at<float>(y, x) = 1.0f;
        continue;
      }
      Eigen::Vector3d h(h0.at<float>(y, x), 0, 0), theta(h[0] / n, 0, 0);
      if (shape.ramp) {
        Eigen::Matrix3d M;
        M << n, m01.at<float>(y, x), m02.at<float>(y, x), m01.at<float>(y, x), m11.at<float>(y, x),
            m12.at<float>(y, x), m02.at<float>(y, x), m12.at<float>(y, x), m22.at<float>(y, x);
        M(1, 1) += 1e-6 * n, M(2, 2) += 1e-6 * n;  // a window of one bright pixel has no slope
        h << h0.at<float>(y, x), h1.at<float>(y, x), h2.at<float>(y, x);
        theta = M.ldlt().solve(h);
      }
      const double misfit = (s.at<float>(y, x) - theta.dot(h)) / samples;
      if (theta[0] < options.shadow_min_gain || theta[0] > options.shadow_max_gain || misfit > tolerance_squared)
        continue;
      gains.alpha.at<float>(y, x) = static_cast<float>(theta[0]);
      gains.beta.at<float>(y, x) = static_cast<float>(theta[1]);
      gains.gamma.at<float>(y, x) = static_cast<float>(theta[2]);
    }
  return gains;
}

// For each pixel x of row y: of the gains the windows of `gains` lend it, the one nearest
// own[x] (the gain that fits the pixel alone), kept in nearest[x] when nearer than it
// already is. Window by window along the row, so that each pixel compares the same gains
// in the same order as one pixel at a time would, in a loop without divisions or branches
// on the image's border.
void NearestLentGains(const WindowGains& gains, int y, const float* own, float* nearest) {
  const int r = gains.shape.radius, cols = gains.alpha.cols;
  for (const cv::Point& offset : gains.shape.neighbours) {  // q = p + offset
    const int qy = y + offset.y;
    if (qy < 0 || qy >= gains.alpha.rows) continue;
    // The plane at the window's point nearest p (no extrapolation beyond the window).
    const float u = std::clamp(float(-offset.x) / r, -1.0f, 1.0f), v = std::clamp(float(-offset.y) / r, -1.0f, 1.0f);
    const float* alpha = gains.alpha.ptr<float>(qy);
    const float* beta = gains.beta.ptr<float>(qy);
    const float* gamma = gains.gamma.ptr<float>(qy);
    const int first = std::max(0, -offset.x), last = std::min(cols, cols - offset.x);
    for (int x = first; x < last; ++x) {  // branch-free: the compiler vectorizes it
      const int qx = x + offset.x;
      const float gain = alpha[qx] + beta[qx] * u + gamma[qx] * v;
      const bool window = alpha[qx] == alpha[qx];  // a shadow window (α not NaN)
      const bool nearer = window & !(std::abs(gain - own[x]) >= std::abs(nearest[x] - own[x]));
      nearest[x] = nearer ? gain : nearest[x];
    }
  }
}

}  // namespace

cv::Mat ShadowRobustDifference(const cv::Mat& image, const cv::Mat& background, double tolerance,
                               const SilhouetteOptions& options) {
  const cv::Mat plain = BackgroundDifference(image, background);  // checks sizes and types
  if (!options.background_shadow_test) return plain;
  const cv::Mat image_unit = ToUnitFloat(image), background_unit = ToUnitFloat(background);
  const int channels = image_unit.channels(), w = options.shadow_window_radius;
  cv::Mat a, b;
  SlopeWeighted(image_unit, background_unit, &a, &b);
  const cv::Mat bb = SumChannels(b.mul(b)), ab = SumChannels(a.mul(b)), aa = SumChannels(a.mul(a));
  // A square whose gain may tilt (a penumbra across it), and lines of the same length in
  // four directions: a shadow edge or a thin shadow (a leg's) is too narrow for any square
  // to fit one gain, but lies along a line that does.
  std::vector<WindowShape> shapes = {Square(w)};
  for (cv::Point direction : {cv::Point(1, 0), cv::Point(0, 1), cv::Point(1, 1), cv::Point(1, -1)})
    shapes.push_back(Line(w, direction));
  std::vector<WindowGains> fitted;
  for (const WindowShape& shape : shapes) fitted.push_back(FitWindowGains(bb, ab, aa, channels, tolerance, shape, options));

  // e(p): the misfit of p under the gain nearest its own among those lent by the shadow
  // windows around it; m = min(d, e).
  cv::Mat robust = plain.clone();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> own(image.cols), gain(image.cols);
  for (int y = 0; y < image.rows; ++y) {
    const float* ap = a.ptr<float>(y);
    const float* bp = b.ptr<float>(y);
    const float* abp = ab.ptr<float>(y);
    const float* bbp = bb.ptr<float>(y);
    float* m = robust.ptr<float>(y);
    for (int x = 0; x < image.cols; ++x) own[x] = bbp[x] > 0 ? abp[x] / bbp[x] : 1.0f;
    std::fill(gain.begin(), gain.end(), nan);
    for (const WindowGains& gains : fitted) NearestLentGains(gains, y, own.data(), gain.data());
    for (int x = 0; x < image.cols; ++x) {
      if (std::isnan(gain[x])) continue;  // no shadow window near p
      float squared = 0;
      for (int c = 0; c < channels; ++c) {
        const float r = ap[x * channels + c] - gain[x] * bp[x * channels + c];
        squared += r * r;
      }
      m[x] = std::min(m[x], std::sqrt(squared / channels));
    }
  }
  return robust;
}

cv::Mat OutsideWorkingVolume(const Camera& camera, const Bounds& bounds, double margin_pixels) {
  cv::Mat outside = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
  if (!bounds.IsValid()) return outside;
  // Points along the 12 edges of the box (distortion bends them), projected.
  constexpr int kSamplesPerEdge = 16;
  std::vector<cv::Point2f> points;
  const double limit = std::max(camera.width(), camera.height());
  for (int edge = 0; edge < 12; ++edge) {
    const int axis = edge / 4, other1 = (axis + 1) % 3, other2 = (axis + 2) % 3;
    for (int s = 0; s <= kSamplesPerEdge; ++s) {
      Eigen::Vector3d X;
      X[axis] = bounds.min[axis] + (bounds.max[axis] - bounds.min[axis]) * s / kSamplesPerEdge;
      X[other1] = edge & 1 ? bounds.max[other1] : bounds.min[other1];
      X[other2] = edge & 2 ? bounds.max[other2] : bounds.min[other2];
      double depth = 0;
      const Eigen::Vector2d pinhole = camera.ProjectUndistorted(X, &depth);
      // Behind the camera, or so far outside that distortion could fold it back: the
      // projection of the box is not a bounded region of the image; nothing is sure.
      if (!(depth > 0) || (camera.HasDistortion() && !camera.InImage(pinhole, -limit))) return outside;
      const Eigen::Vector2d pixel = camera.Project(X);
      points.emplace_back(static_cast<float>(pixel.x()), static_cast<float>(pixel.y()));
    }
  }
  std::vector<cv::Point2f> hull_points;
  cv::convexHull(points, hull_points);
  // Pixel centres are at integer coordinates (DATASET.md), as fillConvexPoly expects;
  // 4 fractional bits keep the sub-pixel outline.
  constexpr int kShift = 4;
  std::vector<cv::Point> hull;
  for (const cv::Point2f& p : hull_points)
    hull.emplace_back(static_cast<int>(std::lround(std::clamp(p.x, -1e6f, 1e6f) * (1 << kShift))),
                      static_cast<int>(std::lround(std::clamp(p.y, -1e6f, 1e6f) * (1 << kShift))));
  cv::Mat volume = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
  cv::fillConvexPoly(volume, hull, cv::Scalar(255), cv::LINE_8, kShift);
  // Farther than the margin from the projection: the distance transform of its outside.
  cv::Mat distance;
  cv::distanceTransform(volume == 0, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  outside = distance > margin_pixels;
  return outside;
}

NoiseThreshold EstimateNoiseThreshold(const cv::Mat& difference, const cv::Mat& surely_background,
                                      const SilhouetteOptions& options) {
  SUBFLOW_CHECK(difference.type() == CV_32FC1, "EstimateNoiseThreshold expects a CV_32FC1 difference");
  NoiseThreshold result;
  if (surely_background.empty()) return result;
  SUBFLOW_CHECK(surely_background.type() == CV_8UC1 && surely_background.size() == difference.size(),
                "EstimateNoiseThreshold expects a CV_8UC1 mask of the difference's size");
  std::vector<float> values;
  for (int y = 0; y < difference.rows; ++y) {
    const float* d = difference.ptr<float>(y);
    const uint8_t* sure = surely_background.ptr<uint8_t>(y);
    for (int x = 0; x < difference.cols; ++x)
      if (sure[x] && std::isfinite(d[x])) values.push_back(d[x]);
  }
  result.pixels = static_cast<long>(values.size());
  if (result.pixels < options.min_background_fraction * difference.total() || result.pixels == 0) return result;
  auto median = [](std::vector<float>* v) {
    std::nth_element(v->begin(), v->begin() + v->size() / 2, v->end());
    return static_cast<double>((*v)[v->size() / 2]);
  };
  result.median = median(&values);
  for (float& v : values) v = static_cast<float>(std::abs(v - result.median));
  result.sigma = 1.4826 * median(&values);
  result.threshold = std::max(options.background_min_threshold,
                              result.median + options.background_noise_factor * result.sigma);
  result.valid = true;
  return result;
}

}  // namespace subflow::vision
