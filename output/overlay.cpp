#include "output/overlay.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace subflow::output {

cv::Mat Overlay(const cv::Mat& image, const cv::Mat& shading, const cv::Mat& mask, const cv::Mat& outline,
                const OverlayOptions& options) {
  SUBFLOW_CHECK(image.size() == shading.size() && image.size() == mask.size() && image.size() == outline.size(),
                "overlay layers of one size");
  cv::Mat blended;
  cv::addWeighted(image, 1.0 - options.alpha, shading, options.alpha, 0.0, blended);
  cv::Mat out = image.clone();
  blended.copyTo(out, mask);
  cv::Mat thick = outline;
  const int radius = std::max(0, static_cast<int>(std::lround(image.cols / 640.0)) - 1);
  if (radius > 0)
    cv::dilate(outline, thick, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1)));
  out.setTo(options.outline_colour, thick);
  return out;
}

cv::Mat ContactSheet(const std::vector<cv::Mat>& pictures, const std::vector<std::string>& labels, int columns,
                     int tile_width) {
  SUBFLOW_CHECK(!pictures.empty() && pictures.size() == labels.size() && columns > 0 && tile_width > 0,
                "contact sheet of labelled pictures");
  int tile_height = 0;
  for (const cv::Mat& picture : pictures)
    tile_height = std::max(tile_height, static_cast<int>(std::lround(picture.rows * double(tile_width) / picture.cols)));
  const int rows = (static_cast<int>(pictures.size()) + columns - 1) / columns;
  cv::Mat sheet(rows * tile_height, columns * tile_width, CV_8UC3, cv::Scalar(255, 255, 255));
  for (std::size_t i = 0; i < pictures.size(); ++i) {
    const int height = static_cast<int>(std::lround(pictures[i].rows * double(tile_width) / pictures[i].cols));
    cv::Mat tile;
    cv::resize(pictures[i], tile, cv::Size(tile_width, height), 0, 0, cv::INTER_AREA);
    const cv::Rect place(static_cast<int>(i % columns) * tile_width, static_cast<int>(i / columns) * tile_height,
                         tile_width, height);
    tile.copyTo(sheet(place));
    cv::putText(sheet, labels[i], {place.x + 4, place.y + 14}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 3,
                cv::LINE_AA);
    cv::putText(sheet, labels[i], {place.x + 4, place.y + 14}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  return sheet;
}

}  // namespace subflow::output
