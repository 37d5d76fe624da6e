#include "output/colour_scale.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace subflow::output {

double ColourScale::Fraction(double value) const {
  if (!(max > min) || !std::isfinite(value)) return 0.0;
  return std::clamp((value - min) / (max - min), 0.0, 1.0);
}

Eigen::Vector3f ColourScale::Srgb(double value) const {
  const auto& table = Table();
  const double position = Fraction(value) * 255.0;
  const int low = std::min(static_cast<int>(position), 254);
  const float weight = static_cast<float>(position - low);
  Eigen::Vector3f colour;
  for (int c = 0; c < 3; ++c)
    colour[c] = ((1.0f - weight) * table[low][c] + weight * table[low + 1][c]) / 255.0f;
  return colour;
}

const std::array<std::array<std::uint8_t, 3>, 256>& ColourScale::Table() {
  static const std::array<std::array<std::uint8_t, 3>, 256> table = [] {
    cv::Mat ramp(256, 1, CV_8UC1), colours;
    for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(i) = static_cast<std::uint8_t>(i);
    cv::applyColorMap(ramp, colours, cv::COLORMAP_VIRIDIS);
    std::array<std::array<std::uint8_t, 3>, 256> rgb{};
    for (int i = 0; i < 256; ++i) {
      const cv::Vec3b bgr = colours.at<cv::Vec3b>(i);
      rgb[i] = {bgr[2], bgr[1], bgr[0]};
    }
    return rgb;
  }();
  return table;
}

float SrgbToLinear(float srgb) {
  return srgb <= 0.04045f ? srgb / 12.92f : std::pow((srgb + 0.055f) / 1.055f, 2.4f);
}

}  // namespace subflow::output
