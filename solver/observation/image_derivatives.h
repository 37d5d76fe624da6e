// Spatio-temporal image derivatives for the normal-flow constraints (method eq. 6, 24).
//
// Conventions
//   Images are gray intensities in [0, 1] as CV_32FC1 (vision::Dataset::Gray); 8-bit and
//   colour inputs are converted (BGR → gray with OpenCV's weights, 8-bit / 255).
//   Pixel (x, y) is the centre of column x, row y (vision/camera.h); samples between
//   centres are bilinear. Spatial smoothing is a Gaussian of σ pixels (kernel ±3σ,
//   replicated border); σ = 0 leaves the image as it is.
//   Spatial gradient: central differences of the smoothed image,
//     I_x(x, y) = (I(x + 1, y) − I(x − 1, y)) / 2,  I_y likewise  (intensity per pixel);
//   replicated at the border; its bilinear interpolation is what SampleImage returns, so
//   intensity and gradient come from the same smoothed image. The differences are taken
//   at sampling time from the intensities (a SmoothedImage holds one plane, not three: the
//   refinement keeps a window's frames of every camera, docs/speed.md), in float as
//   cv::filter2D with the kernel (−½, 0, ½) computes them, to the bit.
//   Temporal derivative at frame f (intensity per frame):
//     I_t = (I(f + 1) − I(f − 1)) / 2, one-sided I(f + 1) − I(f) or I(f) − I(f − 1) at
//   the ends of the sequence. The motion solver itself uses the two-frame form of the same
//   derivative around t = f + ½ (I(f + 1) − I(f), gradients averaged over both frames),
//   see solver/motion/normal_flow_constraints.h.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace subflow::solver {

struct SmoothedImage {
  cv::Mat intensity;  // CV_32FC1, smoothed

  int width() const { return intensity.cols; }
  int height() const { return intensity.rows; }
  bool empty() const { return intensity.empty(); }
};

// Converts `image` to gray CV_32F in [0, 1] (CV_8U / 255, CV_16U / 65535, CV_32F as is;
// 3 or 4 channels BGR(A) → gray). Throws subflow::Error for other types or an empty image.
cv::Mat GrayFloat(const cv::Mat& image);

// The fine structure of `image`'s log intensities, log(I + ε) − G_σ ∗ log(I + ε) (ε =
// kLogEpsilon, G_σ the Gaussian of the file comment), CV_32FC1. A gain (exposure, a light's
// strength) is an offset of log I and goes; shading that varies smoothly across the image
// goes where it is locally linear; the texture's fine detail stays. Brightness constancy on
// it holds through an exposure change (solver/motion/motion_step.h, highpass_sigma).
// Throws subflow::Error for σ ≤ 0 or an unsupported image.
inline constexpr double kLogEpsilon = 0.02;
cv::Mat LogHighPass(const cv::Mat& image, double sigma);

// Smoothed intensity and its spatial gradient (see the file comment). Throws
// subflow::Error for σ < 0 or an unsupported image.
SmoothedImage SmoothImage(const cv::Mat& image, double sigma);

// Bilinear intensity and gradient at `pixel`. Returns false (outputs untouched) when the
// 2×2 neighbourhood is not inside the image.
bool SampleImage(const SmoothedImage& image, const Eigen::Vector2d& pixel, double* intensity,
                 Eigen::Vector2d* gradient);

// Derivatives of a camera's image at frame f for eq. 6: the smoothed image at f, its
// gradient, and I_t by central differences. `previous` / `next` are the frames f − 1 and
// f + 1; either may be empty at the ends of the sequence (one-sided difference), not both.
struct SpatioTemporalDerivatives {
  SmoothedImage spatial;  // I, I_x, I_y at frame f
  cv::Mat temporal;       // CV_32FC1, I_t (per frame)
};
SpatioTemporalDerivatives ComputeSpatioTemporalDerivatives(const cv::Mat& previous,
                                                           const cv::Mat& current,
                                                           const cv::Mat& next, double sigma);

// Bilinear sample of a CV_32FC1 image (false outside, as SampleImage).
bool SampleScalar(const cv::Mat& image, const Eigen::Vector2d& pixel, double* value);

}  // namespace subflow::solver
