// Agreement of two binary silhouettes of the same size (non-zero = object): the figures
// that check a camera convention against an independent renderer (a half-pixel shift
// barely moves IoU but moves the centroid by 0.5 px).
//   IoU       |A ∩ B| / |A ∪ B|  (1 when both are empty)
//   centroid  mean pixel coordinates (x, y) of each mask, pixel-centre convention;
//             offset = centroid(A) − centroid(B) (zero when either is empty)
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace subflow::vision {

struct MaskAgreement {
  double iou = 1.0;
  long long count_a = 0, count_b = 0, intersection = 0;
  Eigen::Vector2d centroid_offset = Eigen::Vector2d::Zero();  // centroid(A) − centroid(B), px
};

// `a`, `b`: CV_8UC1 of equal size. Throws subflow::Error otherwise.
MaskAgreement CompareMasks(const cv::Mat& a, const cv::Mat& b);

}  // namespace subflow::vision
