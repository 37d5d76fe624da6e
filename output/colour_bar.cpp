#include "output/colour_bar.h"

#include <algorithm>
#include <cstdio>

#include <opencv2/imgproc.hpp>

namespace subflow::output {
namespace {

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, value != 0.0 && std::abs(value) < 0.1 ? "%.3f" : "%.2f", value);
  return text;
}

}  // namespace

cv::Mat WithColourBar(const cv::Mat& picture, const ColourScale& scale, ColourBarBox* box) {
  const double font = std::clamp(picture.rows / 600.0, 0.4, 0.8);
  const int thickness = picture.rows > 700 ? 2 : 1;
  const std::string units = "[" + scale.units + "]";
  int baseline = 0;
  const auto width = [&](const std::string& text) {
    return cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, font, thickness, &baseline).width;
  };
  const int line = static_cast<int>(1.8 * cv::getTextSize("Ag", cv::FONT_HERSHEY_SIMPLEX, font, thickness, &baseline).height);
  const int pad = line / 3, bar_width = std::max(10, line);
  int tick_width = 0;
  for (int tick = 0; tick <= 2; ++tick)
    tick_width = std::max(tick_width, width(Number((scale.min + tick * (scale.max - scale.min) / 2.0) * scale.display_factor)));
  const int margin = 2 * pad + std::max({width(scale.label), width(units), bar_width + 6 + tick_width});
  const int height = std::max(picture.rows, 6 * line);
  cv::Mat out(height, picture.cols + margin, CV_8UC3, cv::Scalar(255, 255, 255));
  picture.copyTo(out(cv::Rect(0, 0, picture.cols, picture.rows)));
  ColourBarBox bar;
  bar.left = picture.cols + pad;
  bar.right = bar.left + bar_width - 1;
  bar.top = pad + 2 * line + line / 2;
  bar.bottom = height - line;
  for (int y = bar.top; y <= bar.bottom; ++y) {
    const double fraction = static_cast<double>(bar.bottom - y) / (bar.bottom - bar.top);
    const Eigen::Vector3f rgb = scale.Srgb(scale.min + fraction * (scale.max - scale.min));
    cv::line(out, {bar.left, y}, {bar.right, y}, cv::Scalar(255.0 * rgb[2], 255.0 * rgb[1], 255.0 * rgb[0]), 1);
  }
  const cv::Scalar ink(20, 20, 20);
  const auto text = [&](const std::string& words, int x, int y) {
    cv::putText(out, words, {x, y}, cv::FONT_HERSHEY_SIMPLEX, font, ink, thickness, cv::LINE_AA);
  };
  for (int tick = 0; tick <= 2; ++tick) {
    const int y = bar.bottom - tick * (bar.bottom - bar.top) / 2;
    cv::line(out, {bar.right + 1, y}, {bar.right + 4, y}, ink, 1);
    text(Number((scale.min + tick * (scale.max - scale.min) / 2.0) * scale.display_factor), bar.right + 6, y + line / 4);
  }
  text(scale.label, picture.cols + pad, pad + line);
  text(units, picture.cols + pad, pad + 2 * line);
  if (box) *box = bar;
  return out;
}

}  // namespace subflow::output
