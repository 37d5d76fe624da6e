#include "vision/plain_backdrop.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "vision/silhouettes.h"

namespace subflow::vision {

void PlainBackdropOptions::Check() const {
  const char* source = "plain backdrop options";
  if (!(border_fraction > 0 && border_fraction < 0.5))
    ThrowError(source, "border_fraction", "expected a fraction in (0, 0.5)");
  if (!(spread_quantile > 0 && spread_quantile < 1))
    ThrowError(source, "spread_quantile", "expected a quantile in (0, 1)");
  if (!(max_spread >= 0 && max_spread <= 1)) ThrowError(source, "max_spread", "expected a value in [0, 1]");
}

cv::Mat BorderBand(cv::Size size, const PlainBackdropOptions& options) {
  options.Check();
  cv::Mat band(size, CV_8UC1, cv::Scalar(255));
  const int width = std::max(2, static_cast<int>(std::lround(options.border_fraction *
                                                             std::min(size.width, size.height))));
  if (2 * width < std::min(size.width, size.height))
    band(cv::Rect(width, width, size.width - 2 * width, size.height - 2 * width)).setTo(0);
  return band;
}

PlainBackdrop MeasureBackdrop(const cv::Mat& image, const cv::Mat& sure, const PlainBackdropOptions& options) {
  options.Check();
  const cv::Mat unit = ToUnitFloat(image);
  if (sure.type() != CV_8UC1 || sure.size() != unit.size())
    ThrowError("", "plain backdrop", "expected a CV_8UC1 mask of the image's size");
  const int channels = unit.channels();
  std::vector<std::vector<float>> values(channels);
  for (int y = 0; y < unit.rows; ++y) {
    const float* row = unit.ptr<float>(y);
    const uchar* in = sure.ptr<uchar>(y);
    for (int x = 0; x < unit.cols; ++x)
      if (in[x])
        for (int c = 0; c < channels; ++c) values[c].push_back(row[x * channels + c]);
  }
  PlainBackdrop backdrop;
  backdrop.channels = channels;
  backdrop.sure_pixels = static_cast<int>(values[0].size());
  if (backdrop.sure_pixels == 0) return backdrop;
  const auto quantile = [](std::vector<float>* v, double q) {
    const auto at = v->begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(v->size() - 1));
    std::nth_element(v->begin(), at, v->end());
    return static_cast<double>(*at);
  };
  for (int c = 0; c < channels; ++c) backdrop.colour[c] = quantile(&values[c], 0.5);
  std::vector<float> distance(values[0].size(), 0.0f);
  for (int y = 0, i = 0; y < unit.rows; ++y) {  // the values were reordered: read the image again
    const float* row = unit.ptr<float>(y);
    const uchar* in = sure.ptr<uchar>(y);
    for (int x = 0; x < unit.cols; ++x)
      if (in[x]) {
        for (int c = 0; c < channels; ++c)
          distance[i] = std::max(distance[i], std::abs(row[x * channels + c] - static_cast<float>(backdrop.colour[c])));
        ++i;
      }
  }
  backdrop.spread = quantile(&distance, options.spread_quantile);
  backdrop.plain = backdrop.spread <= options.max_spread;
  return backdrop;
}

cv::Mat BackdropImage(const cv::Mat& image, const PlainBackdrop& backdrop) {
  return cv::Mat(image.size(), CV_MAKETYPE(CV_32F, backdrop.channels), backdrop.colour);
}

}  // namespace subflow::vision
