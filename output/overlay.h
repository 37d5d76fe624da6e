// Checking a reconstruction against its input images at a glance:
//   Overlay       the (undistorted) input image, the shaded surface blended over it with
//                 weight `alpha` where the surface covers the image, and the surface's
//                 outline drawn opaque in `outline_colour` (thickened on large images).
//   ContactSheet  pictures side by side in a grid of `columns`, each scaled to
//                 `tile_width` and labelled in its corner.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace subflow::output {

struct OverlayOptions {
  double alpha = 0.45;                                 // weight of the shaded surface
  cv::Scalar outline_colour = cv::Scalar(255, 0, 255);  // BGR (magenta: rare in real takes)
};

// image, shading: CV_8UC3 of one size; mask, outline: CV_8UC1 (255 = surface / outline).
cv::Mat Overlay(const cv::Mat& image, const cv::Mat& shading, const cv::Mat& mask, const cv::Mat& outline,
                const OverlayOptions& options = {});

cv::Mat ContactSheet(const std::vector<cv::Mat>& pictures, const std::vector<std::string>& labels, int columns,
                     int tile_width);

}  // namespace subflow::output
