#include "vision/mask_agreement.h"

#include <cstdint>

#include "core/error.h"

namespace subflow::vision {

MaskAgreement CompareMasks(const cv::Mat& a, const cv::Mat& b) {
  if (a.type() != CV_8UC1 || b.type() != CV_8UC1 || a.size() != b.size())
    ThrowError("CompareMasks", "masks", "expected two CV_8UC1 masks of the same size");
  MaskAgreement result;
  Eigen::Vector2d sum_a = Eigen::Vector2d::Zero(), sum_b = Eigen::Vector2d::Zero();
  for (int y = 0; y < a.rows; ++y) {
    const auto* row_a = a.ptr<std::uint8_t>(y);
    const auto* row_b = b.ptr<std::uint8_t>(y);
    for (int x = 0; x < a.cols; ++x) {
      const bool in_a = row_a[x] != 0, in_b = row_b[x] != 0;
      if (in_a) {
        ++result.count_a;
        sum_a += Eigen::Vector2d(x, y);
      }
      if (in_b) {
        ++result.count_b;
        sum_b += Eigen::Vector2d(x, y);
      }
      if (in_a && in_b) ++result.intersection;
    }
  }
  const long long union_count = result.count_a + result.count_b - result.intersection;
  result.iou = union_count > 0 ? static_cast<double>(result.intersection) / union_count : 1.0;
  if (result.count_a > 0 && result.count_b > 0)
    result.centroid_offset = sum_a / static_cast<double>(result.count_a) - sum_b / static_cast<double>(result.count_b);
  return result;
}

}  // namespace subflow::vision
